//! The JSON encoding of REXS (`.rexsj`): `{"model": {version, applicationId, ..., relations:
//! [{id, type, order?, refs: [{id, role, hint}]}], components: [{id, type, name, attributes:
//! [{id, unit, <value type>: value}]}]}}`, the value's key naming its REXS value type
//! (`floating_point`, `integer`, `boolean`, `enum`, `string`, `reference_component`,
//! `floating_point_array`, ...).

use super::{Attribute, Component, LoadCase, Model, Ref, Relation, RexsError, Value};
use serde_json::{json, Map, Value as Json};

/// What is wrong with a text that does not parse as JSON; nesting beyond the parser's limit
/// is named as such (a REXS model nests a few levels).
fn json_error(e: &serde_json::Error) -> String {
    if e.to_string().starts_with("recursion limit exceeded") {
        format!(
            "JSON nested deeper than 128 levels (at line {} column {}; a REXS model nests 5)",
            e.line(),
            e.column()
        )
    } else {
        format!("JSON: {e}")
    }
}

/// Parses a `.rexsj` document.
pub(super) fn parse(text: &str, name: &str) -> Result<Model, RexsError> {
    let err = |message: String| RexsError::Format {
        path: name.to_string(),
        message,
    };
    let doc: Json = serde_json::from_str(text).map_err(|e| err(json_error(&e)))?;
    let m = doc
        .get("model")
        .and_then(Json::as_object)
        .ok_or_else(|| err("JSON without a \"model\" object".into()))?;
    let text_of = |k: &str| m.get(k).and_then(Json::as_str).unwrap_or("").to_string();
    let mut model = Model {
        version: text_of("version"),
        application_id: text_of("applicationId"),
        application_version: text_of("applicationVersion"),
        date: text_of("date"),
        ..Model::default()
    };
    for (i, r) in array(m, "relations").iter().enumerate() {
        model
            .relations
            .push(relation(r).map_err(|e| err(format!("relations[{i}]: {e}")))?);
    }
    for (i, c) in array(m, "components").iter().enumerate() {
        model
            .components
            .push(component(c).map_err(|e| err(format!("components[{i}]: {e}")))?);
    }
    if let Some(spectrum) = m.get("load_spectrum").and_then(Json::as_object) {
        for (i, case) in array(spectrum, "load_cases").iter().enumerate() {
            let at = |e: String| err(format!("load_spectrum.load_cases[{i}]: {e}"));
            let mut components = Vec::new();
            for c in case
                .get("components")
                .and_then(Json::as_array)
                .map_or(&[][..], |v| v)
            {
                components.push(component(c).map_err(at)?);
            }
            let id = id_of(case).map_err(at)?;
            model.load_cases.push(LoadCase { id, components });
        }
    }
    Ok(model)
}

fn array<'a>(m: &'a Map<String, Json>, key: &str) -> &'a [Json] {
    m.get(key).and_then(Json::as_array).map_or(&[], |v| v)
}

fn id_of(v: &Json) -> Result<u64, String> {
    let id = v.get("id").ok_or("no \"id\"")?;
    id.as_u64()
        .or_else(|| id.as_str().and_then(|s| s.trim().parse().ok()))
        .ok_or_else(|| format!("id {id} is not a non-negative integer"))
}

fn text(v: &Json, key: &str) -> String {
    v.get(key).and_then(Json::as_str).unwrap_or("").to_string()
}

fn relation(r: &Json) -> Result<Relation, String> {
    let refs = r
        .get("refs")
        .and_then(Json::as_array)
        .map_or(&[][..], |v| v)
        .iter()
        .map(|x| {
            Ok(Ref {
                id: id_of(x).map_err(|e| format!("ref: {e}"))?,
                role: text(x, "role"),
                hint: text(x, "hint"),
            })
        })
        .collect::<Result<Vec<_>, String>>()?;
    Ok(Relation {
        id: id_of(r)?,
        kind: text(r, "type"),
        order: r.get("order").and_then(Json::as_i64),
        refs,
    })
}

fn component(c: &Json) -> Result<Component, String> {
    let id = id_of(c)?;
    let mut attributes = Vec::new();
    for a in c
        .get("attributes")
        .and_then(Json::as_array)
        .map_or(&[][..], |v| v)
    {
        let aid = text(a, "id");
        if aid.is_empty() {
            return Err(format!("component {id}: an attribute without an \"id\""));
        }
        attributes.push(Attribute {
            unit: text(a, "unit"),
            value: value(a).map_err(|e| format!("component {id}: attribute {aid}: {e}"))?,
            id: aid,
        });
    }
    Ok(Component {
        id,
        kind: text(c, "type"),
        name: text(c, "name"),
        attributes,
    })
}

/// The value of an attribute object, by the key that names its type.
fn value(a: &Json) -> Result<Value, String> {
    let obj = a.as_object().ok_or("not an object")?;
    let (key, v) = obj
        .iter()
        .find(|(k, _)| k.as_str() != "id" && k.as_str() != "unit")
        .ok_or("no value")?;
    // A value that does not fit its type (writers put null for "not set") is kept raw: it is
    // listed when unused and refused by name when the import needs it.
    let raw = || Value::Raw(format!("{key}: {v}"));
    let floats =
        |v: &Json| -> Option<Vec<f64>> { v.as_array()?.iter().map(Json::as_f64).collect() };
    let typed = match key.as_str() {
        "floating_point" => v.as_f64().map(Value::Float),
        "integer" => v.as_i64().map(Value::Integer),
        "boolean" => v.as_bool().map(Value::Boolean),
        "enum" => v.as_str().map(|s| Value::Enum(s.to_string())),
        "string" | "file_reference" | "date_time" => v.as_str().map(|s| Value::Text(s.to_string())),
        "reference_component" => v.as_u64().map(Value::Reference),
        "floating_point_array" => floats(v).map(Value::FloatArray),
        "integer_array" => v
            .as_array()
            .and_then(|x| x.iter().map(Json::as_i64).collect())
            .map(Value::IntegerArray),
        "floating_point_matrix" => v
            .as_array()
            .and_then(|rows| rows.iter().map(floats).collect())
            .map(Value::FloatMatrix),
        _ => None,
    };
    Ok(typed.unwrap_or_else(raw))
}

/// Writes a model as a `.rexsj` document.
pub(super) fn write(model: &Model) -> String {
    let relations: Vec<Json> = model
        .relations
        .iter()
        .map(|r| {
            let refs: Vec<Json> = r
                .refs
                .iter()
                .map(|x| json!({"id": x.id, "role": x.role, "hint": x.hint}))
                .collect();
            let mut o = json!({"id": r.id, "type": r.kind, "refs": refs});
            if let Some(order) = r.order {
                o["order"] = json!(order);
            }
            o
        })
        .collect();
    let components: Vec<Json> = model.components.iter().map(component_json).collect();
    let mut doc = json!({"model": {
        "applicationId": model.application_id,
        "applicationVersion": model.application_version,
        "date": model.date,
        "version": model.version,
        "relations": relations,
        "components": components,
    }});
    if !model.load_cases.is_empty() {
        let cases: Vec<Json> = model
            .load_cases
            .iter()
            .map(|case| {
                let components: Vec<Json> = case.components.iter().map(component_json).collect();
                json!({"id": case.id, "components": components})
            })
            .collect();
        doc["model"]["load_spectrum"] = json!({"id": 1, "load_cases": cases});
    }
    let mut text = serde_json::to_string_pretty(&doc).unwrap_or_default();
    text.push('\n');
    text
}

/// A component as a JSON object.
fn component_json(c: &Component) -> Json {
    let attributes: Vec<Json> = c
        .attributes
        .iter()
        .map(|a| {
            let mut o = Map::new();
            o.insert("id".into(), json!(a.id));
            o.insert("unit".into(), json!(a.unit));
            let (k, v) = typed(&a.value);
            o.insert(k.into(), v);
            Json::Object(o)
        })
        .collect();
    json!({"id": c.id, "type": c.kind, "name": c.name, "attributes": attributes})
}

/// The JSON key and value of a typed value (text values as `string`).
fn typed(v: &Value) -> (&'static str, Json) {
    match v {
        Value::Float(x) => ("floating_point", json!(x)),
        Value::Integer(i) => ("integer", json!(i)),
        Value::Boolean(b) => ("boolean", json!(b)),
        Value::Enum(s) => ("enum", json!(s)),
        Value::Text(s) | Value::Raw(s) => ("string", json!(s)),
        Value::Reference(id) => ("reference_component", json!(id)),
        Value::FloatArray(a) => ("floating_point_array", json!(a)),
        Value::IntegerArray(a) => ("integer_array", json!(a)),
        Value::FloatMatrix(m) => ("floating_point_matrix", json!(m)),
    }
}
