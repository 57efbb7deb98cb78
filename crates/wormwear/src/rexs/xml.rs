//! The XML encoding of REXS (`.rexs`), read and written with quick-xml.
//!
//! `<model version applicationId applicationVersion date>` holds `<relations>` (each
//! `<relation id type [order]>` with `<ref id role hint/>`) and `<components>` (each
//! `<component id name type>` with `<attribute id unit>`). A scalar attribute is its text; an
//! array is `<array><c>..</c>...</array>`, a matrix `<matrix><r><c>..</c></r>...</matrix>`. XML
//! carries no value types, so scalars are kept as text ([`Value::Text`]) and typed when used.

use super::{Attribute, Component, LoadCase, Model, Ref, Relation, RexsError, Value};
use quick_xml::events::{BytesDecl, BytesEnd, BytesStart, BytesText, Event};
use quick_xml::{Reader, Writer};
use std::collections::HashMap;

/// Parses a `.rexs` document.
pub(super) fn parse(text: &str, name: &str) -> Result<Model, RexsError> {
    let mut reader = Reader::from_str(text);
    reader.config_mut().trim_text(true);
    let mut p = Parser {
        name,
        model: Model::default(),
        seen_model: false,
        relation: None,
        component: None,
        attribute: None,
        load_case: None,
        in_accumulation: false,
    };
    let mut open: Vec<String> = Vec::new();
    loop {
        let at = reader.buffer_position();
        let event = reader
            .read_event()
            .map_err(|e| p.error(at, e.to_string()))?;
        match event {
            Event::Start(e) => {
                open.push(String::from_utf8_lossy(e.name().as_ref()).into_owned());
                p.open(&e, at, false)?
            }
            Event::Empty(e) => p.open(&e, at, true)?,
            Event::End(e) => {
                open.pop();
                p.close(e.name().as_ref(), at)?
            }
            Event::Text(t) => {
                let s = t.unescape().map_err(|e| p.error(at, e.to_string()))?;
                p.text(&s);
            }
            Event::CData(t) => p.text(&String::from_utf8_lossy(&t)),
            Event::Eof => {
                if let Some(tag) = open.last() {
                    return Err(
                        p.error(at, format!("the document ends inside <{tag}> (truncated?)"))
                    );
                }
                break;
            }
            _ => {}
        }
    }
    if !p.seen_model {
        return Err(p.error(0, "no <model> element".into()));
    }
    Ok(p.model)
}

/// An attribute being read: its id and unit, and what its content has given so far.
struct OpenAttribute {
    id: String,
    unit: String,
    text: String,
    /// Inside `<array>`: the cells; `coded`: a base64-coded array (kept raw).
    array: Option<Vec<String>>,
    coded: bool,
    /// Inside `<matrix>`: the finished rows and the row being read.
    matrix: Option<Vec<Vec<String>>>,
    row: Option<Vec<String>>,
    in_cell: bool,
}

struct Parser<'a> {
    name: &'a str,
    model: Model,
    seen_model: bool,
    relation: Option<Relation>,
    component: Option<Component>,
    attribute: Option<OpenAttribute>,
    /// The `<load_case>` being read (its components are the varied attributes).
    load_case: Option<LoadCase>,
    /// Inside the load spectrum's `<accumulation>` (not read).
    in_accumulation: bool,
}

impl Parser<'_> {
    fn error(&self, at: u64, message: String) -> RexsError {
        RexsError::Format {
            path: self.name.to_string(),
            message: format!("XML at byte {at}: {message}"),
        }
    }

    fn attrs(&self, e: &BytesStart, at: u64) -> Result<HashMap<String, String>, RexsError> {
        let mut map = HashMap::new();
        for a in e.attributes() {
            let a = a.map_err(|err| self.error(at, err.to_string()))?;
            let key = String::from_utf8_lossy(a.key.as_ref()).into_owned();
            let value = a
                .unescape_value()
                .map_err(|err| self.error(at, err.to_string()))?;
            map.insert(key, value.into_owned());
        }
        Ok(map)
    }

    fn id(&self, attrs: &HashMap<String, String>, tag: &str, at: u64) -> Result<u64, RexsError> {
        let raw = attrs
            .get("id")
            .ok_or_else(|| self.error(at, format!("<{tag}> without an id")))?;
        raw.trim().parse().map_err(|_| {
            self.error(
                at,
                format!("<{tag} id=\"{raw}\">: the id must be an integer"),
            )
        })
    }

    fn open(&mut self, e: &BytesStart, at: u64, empty: bool) -> Result<(), RexsError> {
        let tag = String::from_utf8_lossy(e.name().as_ref()).into_owned();
        match tag.as_str() {
            "model" => self.open_model(e, at),
            "relation" => self.open_relation(e, at, empty),
            "ref" => self.open_ref(e, at),
            "component" => self.open_component(e, at, empty),
            "load_case" => {
                let id = self.id(&self.attrs(e, at)?, "load_case", at)?;
                let case = LoadCase {
                    id,
                    components: Vec::new(),
                };
                match empty {
                    true => self.model.load_cases.push(case),
                    false => self.load_case = Some(case),
                }
                Ok(())
            }
            "accumulation" => {
                self.in_accumulation = !empty;
                Ok(())
            }
            "attribute" if self.component.is_some() => self.open_attribute(e, at, empty),
            "array" | "matrix" | "r" | "c" => {
                let coded = tag == "array" && self.attrs(e, at)?.contains_key("coding");
                if let Some(att) = self.attribute.as_mut() {
                    open_value(att, &tag, coded, empty);
                }
                Ok(())
            }
            _ => Ok(()),
        }
    }

    fn open_model(&mut self, e: &BytesStart, at: u64) -> Result<(), RexsError> {
        let a = self.attrs(e, at)?;
        self.seen_model = true;
        let get = |k: &str| a.get(k).cloned().unwrap_or_default();
        self.model.version = get("version");
        self.model.application_id = get("applicationId");
        self.model.application_version = get("applicationVersion");
        self.model.date = get("date");
        Ok(())
    }

    fn open_relation(&mut self, e: &BytesStart, at: u64, empty: bool) -> Result<(), RexsError> {
        let a = self.attrs(e, at)?;
        let relation = Relation {
            id: self.id(&a, "relation", at)?,
            kind: a.get("type").cloned().unwrap_or_default(),
            order: a.get("order").and_then(|o| o.trim().parse().ok()),
            refs: Vec::new(),
        };
        match empty {
            true => self.model.relations.push(relation),
            false => self.relation = Some(relation),
        }
        Ok(())
    }

    fn open_ref(&mut self, e: &BytesStart, at: u64) -> Result<(), RexsError> {
        let a = self.attrs(e, at)?;
        let r = Ref {
            id: self.id(&a, "ref", at)?,
            role: a.get("role").cloned().unwrap_or_default(),
            hint: a.get("hint").cloned().unwrap_or_default(),
        };
        match self.relation.as_mut() {
            Some(rel) => {
                rel.refs.push(r);
                Ok(())
            }
            None => Err(self.error(at, "<ref> outside a <relation>".into())),
        }
    }

    fn open_component(&mut self, e: &BytesStart, at: u64, empty: bool) -> Result<(), RexsError> {
        let a = self.attrs(e, at)?;
        let component = Component {
            id: self.id(&a, "component", at)?,
            kind: a.get("type").cloned().unwrap_or_default(),
            name: a.get("name").cloned().unwrap_or_default(),
            attributes: Vec::new(),
        };
        match empty {
            true => self.finish_component(component),
            false => self.component = Some(component),
        }
        Ok(())
    }

    /// A component read: the master model's, the open load case's, or the accumulation's
    /// (dropped).
    fn finish_component(&mut self, c: Component) {
        if self.in_accumulation {
            return;
        }
        match self.load_case.as_mut() {
            Some(case) => case.components.push(c),
            None => self.model.components.push(c),
        }
    }

    fn open_attribute(&mut self, e: &BytesStart, at: u64, empty: bool) -> Result<(), RexsError> {
        let a = self.attrs(e, at)?;
        let id = a
            .get("id")
            .cloned()
            .ok_or_else(|| self.error(at, "<attribute> without an id".into()))?;
        self.attribute = Some(OpenAttribute {
            id,
            unit: a.get("unit").cloned().unwrap_or_default(),
            text: String::new(),
            array: None,
            coded: false,
            matrix: None,
            row: None,
            in_cell: false,
        });
        if empty {
            self.close("attribute".as_bytes(), at)?;
        }
        Ok(())
    }

    fn text(&mut self, s: &str) {
        if let Some(att) = self.attribute.as_mut() {
            if att.in_cell {
                push_cell(att, s.to_string());
                att.in_cell = false;
            } else {
                att.text.push_str(s);
            }
        }
    }

    fn close(&mut self, tag: &[u8], at: u64) -> Result<(), RexsError> {
        match tag {
            b"relation" => {
                if let Some(r) = self.relation.take() {
                    self.model.relations.push(r);
                }
            }
            b"component" => {
                if let Some(c) = self.component.take() {
                    self.finish_component(c);
                }
            }
            b"load_case" => {
                if let Some(case) = self.load_case.take() {
                    self.model.load_cases.push(case);
                }
            }
            b"accumulation" => self.in_accumulation = false,
            b"attribute" => {
                if let Some(att) = self.attribute.take() {
                    let value = attribute_value(&att)
                        .map_err(|m| self.error(at, format!("attribute {}: {m}", att.id)))?;
                    if let Some(c) = self.component.as_mut() {
                        c.attributes.push(Attribute {
                            id: att.id,
                            unit: att.unit,
                            value,
                        });
                    }
                }
            }
            b"r" => {
                if let Some(att) = self.attribute.as_mut() {
                    if let (Some(m), Some(row)) = (att.matrix.as_mut(), att.row.take()) {
                        m.push(row);
                    }
                }
            }
            b"c" => {
                if let Some(att) = self.attribute.as_mut() {
                    if att.in_cell {
                        push_cell(att, String::new());
                        att.in_cell = false;
                    }
                }
            }
            _ => {}
        }
        Ok(())
    }
}

/// An `<array>`, `<matrix>`, `<r>` or `<c>` inside an attribute.
fn open_value(att: &mut OpenAttribute, tag: &str, coded: bool, empty: bool) {
    match tag {
        "array" => {
            att.array = Some(Vec::new());
            att.coded = coded;
        }
        "matrix" => att.matrix = Some(Vec::new()),
        "r" => att.row = Some(Vec::new()),
        _ => {
            att.in_cell = !empty;
            if empty {
                push_cell(att, String::new());
            }
        }
    }
}

fn push_cell(att: &mut OpenAttribute, s: String) {
    if let Some(row) = att.row.as_mut() {
        row.push(s);
    } else if let Some(a) = att.array.as_mut() {
        a.push(s);
    }
}

/// The value of a finished attribute: an array or matrix of numbers, or its text.
fn attribute_value(att: &OpenAttribute) -> Result<Value, String> {
    let number = |s: &String| -> Result<f64, String> {
        s.trim()
            .parse::<f64>()
            .map_err(|_| format!("array cell \"{s}\" is not a number"))
    };
    if let Some(m) = &att.matrix {
        let rows = m
            .iter()
            .map(|r| r.iter().map(number).collect::<Result<Vec<_>, _>>())
            .collect::<Result<Vec<_>, _>>();
        return Ok(match rows {
            Ok(rows) => Value::FloatMatrix(rows),
            Err(_) => Value::Raw(format!("{m:?}")),
        });
    }
    if att.coded {
        return Ok(Value::Raw(att.text.trim().to_string()));
    }
    if let Some(a) = &att.array {
        if a.is_empty() && !att.text.trim().is_empty() {
            return Ok(Value::Raw(att.text.trim().to_string()));
        }
        return Ok(match a.iter().map(number).collect::<Result<Vec<_>, _>>() {
            Ok(v) => Value::FloatArray(v),
            Err(_) => Value::Raw(a.join(" ")),
        });
    }
    Ok(Value::Text(att.text.trim().to_string()))
}

/// Writes a model as a `.rexs` document (UTF-8, two-space indent).
pub(super) fn write(model: &Model) -> String {
    let mut w = Writer::new_with_indent(Vec::new(), b' ', 2);
    // Writing into a Vec cannot fail; the results are ignored on that ground.
    let _ = w.write_event(Event::Decl(BytesDecl::new(
        "1.0",
        Some("UTF-8"),
        Some("no"),
    )));
    let model_tag = BytesStart::new("model").with_attributes([
        ("applicationId", model.application_id.as_str()),
        ("applicationVersion", model.application_version.as_str()),
        ("date", model.date.as_str()),
        ("version", model.version.as_str()),
    ]);
    let _ = w.write_event(Event::Start(model_tag));
    let _ = w.write_event(Event::Start(BytesStart::new("relations")));
    for r in &model.relations {
        let id = r.id.to_string();
        let order = r.order.map(|o| o.to_string());
        let mut tag = BytesStart::new("relation").with_attributes([("id", id.as_str())]);
        if let Some(o) = &order {
            tag.push_attribute(("order", o.as_str()));
        }
        tag.push_attribute(("type", r.kind.as_str()));
        let _ = w.write_event(Event::Start(tag));
        for x in &r.refs {
            let id = x.id.to_string();
            let tag = BytesStart::new("ref").with_attributes([
                ("hint", x.hint.as_str()),
                ("id", id.as_str()),
                ("role", x.role.as_str()),
            ]);
            let _ = w.write_event(Event::Empty(tag));
        }
        let _ = w.write_event(Event::End(BytesEnd::new("relation")));
    }
    let _ = w.write_event(Event::End(BytesEnd::new("relations")));
    let _ = w.write_event(Event::Start(BytesStart::new("components")));
    for c in &model.components {
        write_component(&mut w, c);
    }
    let _ = w.write_event(Event::End(BytesEnd::new("components")));
    if !model.load_cases.is_empty() {
        let spectrum = BytesStart::new("load_spectrum").with_attributes([("id", "1")]);
        let _ = w.write_event(Event::Start(spectrum));
        for case in &model.load_cases {
            let id = case.id.to_string();
            let tag = BytesStart::new("load_case").with_attributes([("id", id.as_str())]);
            let _ = w.write_event(Event::Start(tag));
            for c in &case.components {
                write_component(&mut w, c);
            }
            let _ = w.write_event(Event::End(BytesEnd::new("load_case")));
        }
        let _ = w.write_event(Event::End(BytesEnd::new("load_spectrum")));
    }
    let _ = w.write_event(Event::End(BytesEnd::new("model")));
    let mut text = String::from_utf8(w.into_inner()).unwrap_or_default();
    text.push('\n');
    text
}

fn write_component(w: &mut Writer<Vec<u8>>, c: &Component) {
    let id = c.id.to_string();
    let tag = BytesStart::new("component").with_attributes([
        ("id", id.as_str()),
        ("name", c.name.as_str()),
        ("type", c.kind.as_str()),
    ]);
    let _ = w.write_event(Event::Start(tag));
    for a in &c.attributes {
        let tag = BytesStart::new("attribute")
            .with_attributes([("id", a.id.as_str()), ("unit", a.unit.as_str())]);
        let cells = |w: &mut Writer<Vec<u8>>, values: Vec<String>| {
            for v in values {
                let _ = w.write_event(Event::Start(BytesStart::new("c")));
                let _ = w.write_event(Event::Text(BytesText::new(&v)));
                let _ = w.write_event(Event::End(BytesEnd::new("c")));
            }
        };
        match &a.value {
            Value::FloatArray(v) => {
                let _ = w.write_event(Event::Start(tag));
                let _ = w.write_event(Event::Start(BytesStart::new("array")));
                cells(w, v.iter().map(|x| x.to_string()).collect());
                let _ = w.write_event(Event::End(BytesEnd::new("array")));
            }
            Value::IntegerArray(v) => {
                let _ = w.write_event(Event::Start(tag));
                let _ = w.write_event(Event::Start(BytesStart::new("array")));
                cells(w, v.iter().map(|x| x.to_string()).collect());
                let _ = w.write_event(Event::End(BytesEnd::new("array")));
            }
            Value::FloatMatrix(m) => {
                let _ = w.write_event(Event::Start(tag));
                let _ = w.write_event(Event::Start(BytesStart::new("matrix")));
                for row in m {
                    let _ = w.write_event(Event::Start(BytesStart::new("r")));
                    cells(w, row.iter().map(|x| x.to_string()).collect());
                    let _ = w.write_event(Event::End(BytesEnd::new("r")));
                }
                let _ = w.write_event(Event::End(BytesEnd::new("matrix")));
            }
            scalar => {
                let _ = w.write_event(Event::Start(tag));
                let text = match scalar {
                    Value::Reference(id) => id.to_string(),
                    other => other.to_string(),
                };
                let _ = w.write_event(Event::Text(BytesText::new(&text)));
            }
        }
        let _ = w.write_event(Event::End(BytesEnd::new("attribute")));
    }
    let _ = w.write_event(Event::End(BytesEnd::new("component")));
}
