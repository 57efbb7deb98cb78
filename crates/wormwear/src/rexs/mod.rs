//! REXS, the FVA's gear-unit interchange format (versions 1.x): read and write `.rexs` (XML),
//! `.rexsj` (JSON) and `.rexsz` (a zip holding one of them), take a worm stage out of a model as
//! a gear file ([`import`]) and write a stage with our results back ([`export`]).
//!
//! The model is kept as the file has it: components with typed attributes (each with its
//! unit), and relations between components by id and role. Only [`import`] interprets it.
//! Component types, attribute ids, units and relation roles are those of the REXS database
//! (rexs_model_1.4 / rexs_schema_1.5, published by the FVA).

pub mod export;
pub mod import;
mod json;
pub mod units;
mod xml;

use std::path::Path;

/// One REXS model: what the file's `<model>` holds.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Model {
    /// REXS version of the file, e.g. "1.4".
    pub version: String,
    pub application_id: String,
    pub application_version: String,
    pub date: String,
    pub relations: Vec<Relation>,
    pub components: Vec<Component>,
    /// The load cases of the model's load spectrum (`<load_spectrum>`; empty: none). Each is a
    /// sub-model holding only the attributes that vary, on components of the master model's
    /// ids; its accumulation sub-model is not read.
    pub load_cases: Vec<LoadCase>,
}

/// One load case of a REXS load spectrum: the varied attributes, by component id.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadCase {
    pub id: u64,
    pub components: Vec<Component>,
}

/// A relation between components (stage, assembly, side, flank, manufacturing_step,
/// reference, ...).
#[derive(Debug, Clone, PartialEq)]
pub struct Relation {
    pub id: u64,
    /// Relation type, e.g. "stage".
    pub kind: String,
    pub order: Option<i64>,
    pub refs: Vec<Ref>,
}

/// One member of a relation.
#[derive(Debug, Clone, PartialEq)]
pub struct Ref {
    pub id: u64,
    pub role: String,
    /// The component type the file names beside the id (informative).
    pub hint: String,
}

/// A component with its attributes.
#[derive(Debug, Clone, PartialEq)]
pub struct Component {
    pub id: u64,
    /// Component type, e.g. "worm_gear".
    pub kind: String,
    pub name: String,
    pub attributes: Vec<Attribute>,
}

/// An attribute: its REXS id, its unit as the file writes it, and its value.
#[derive(Debug, Clone, PartialEq)]
pub struct Attribute {
    pub id: String,
    pub unit: String,
    pub value: Value,
}

/// An attribute value with its REXS value type.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    Float(f64),
    Integer(i64),
    Boolean(bool),
    /// An enum value (REXS value type `enum`).
    Enum(String),
    /// Free text (REXS `string`, `file_reference`, `date_time`).
    Text(String),
    /// A component id (REXS `reference_component`).
    Reference(u64),
    FloatArray(Vec<f64>),
    IntegerArray(Vec<i64>),
    FloatMatrix(Vec<Vec<f64>>),
    /// A value this reader does not decode (coded arrays, other array kinds): the raw text,
    /// kept so that it can be listed.
    Raw(String),
}

impl std::fmt::Display for Value {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Value::Float(x) => write!(f, "{x}"),
            Value::Integer(i) => write!(f, "{i}"),
            Value::Boolean(b) => write!(f, "{b}"),
            Value::Enum(s) | Value::Text(s) | Value::Raw(s) => write!(f, "{s}"),
            Value::Reference(id) => write!(f, "component {id}"),
            Value::FloatArray(v) => write!(f, "{v:?}"),
            Value::IntegerArray(v) => write!(f, "{v:?}"),
            Value::FloatMatrix(m) => write!(f, "{m:?}"),
        }
    }
}

/// Why a REXS file could not be read or used. Every message names the file part, component
/// or attribute at fault and what is needed; all are input errors (exit code 2).
#[derive(Debug, thiserror::Error)]
pub enum RexsError {
    #[error("cannot read {path}: {message}")]
    Io { path: String, message: String },
    #[error("{path}: not a REXS file: {message}")]
    Format { path: String, message: String },
    #[error("component {component} ({kind}): attribute {attribute}: {message}")]
    Attribute {
        component: u64,
        kind: String,
        attribute: String,
        message: String,
    },
    #[error("{0}")]
    Model(String),
}

impl RexsError {
    pub(crate) fn attribute(c: &Component, attribute: &str, message: impl Into<String>) -> Self {
        RexsError::Attribute {
            component: c.id,
            kind: c.kind.clone(),
            attribute: attribute.to_string(),
            message: message.into(),
        }
    }
}

/// File encodings of a REXS model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Encoding {
    /// `.rexs`: XML.
    Xml,
    /// `.rexsj`: JSON.
    Json,
}

impl Encoding {
    /// The encoding a file name implies (`.rexsj` / `.json`: JSON, otherwise XML).
    pub fn of_path(path: &Path) -> Self {
        match path.extension().and_then(|e| e.to_str()) {
            Some(e) if e.eq_ignore_ascii_case("rexsj") || e.eq_ignore_ascii_case("json") => {
                Encoding::Json
            }
            _ => Encoding::Xml,
        }
    }
}

/// Reads a `.rexs`, `.rexsj` or `.rexsz` file. The encoding is taken from the content (a zip,
/// a JSON object or XML), so a misnamed file still reads.
pub fn read(path: &Path) -> Result<Model, RexsError> {
    let name = path.display().to_string();
    let bytes =
        crate::files::read_bytes(path, crate::files::REXS_LIMIT).map_err(|e| RexsError::Io {
            path: name.clone(),
            message: e.to_string(),
        })?;
    parse_bytes(&bytes, &name)
}

/// Parses the bytes of a REXS file (XML, JSON or a zip holding one); `name` is used in errors.
pub fn parse_bytes(bytes: &[u8], name: &str) -> Result<Model, RexsError> {
    if bytes.starts_with(b"PK\x03\x04") {
        return read_zip(bytes, name);
    }
    let text = std::str::from_utf8(bytes).map_err(|e| RexsError::Format {
        path: name.to_string(),
        message: format!("not UTF-8 text ({e})"),
    })?;
    let trimmed = text.trim_start_matches('\u{feff}').trim_start();
    if trimmed.starts_with('{') {
        json::parse(trimmed, name)
    } else if trimmed.starts_with('<') {
        xml::parse(trimmed, name)
    } else if trimmed.starts_with('[') {
        Err(RexsError::Format {
            path: name.to_string(),
            message: "a JSON array; a REXS JSON file is the object {\"model\": ...}".into(),
        })
    } else {
        Err(RexsError::Format {
            path: name.to_string(),
            message: "expected XML (<model ...>), JSON ({\"model\": ...}) or a zip archive".into(),
        })
    }
}

/// A `.rexsz`: the first `.rexs`/`.rexsj` member of the archive.
fn read_zip(bytes: &[u8], name: &str) -> Result<Model, RexsError> {
    use std::io::Read;
    let format = |message: String| RexsError::Format {
        path: name.to_string(),
        message,
    };
    let mut archive = zip::ZipArchive::new(std::io::Cursor::new(bytes))
        .map_err(|e| format(format!("unreadable zip archive ({e})")))?;
    let members: Vec<(usize, String)> = (0..archive.len())
        .filter_map(|i| {
            let n = archive.name_for_index(i)?.ok()?.to_string();
            let lower = n.to_ascii_lowercase();
            (lower.ends_with(".rexs") || lower.ends_with(".rexsj")).then_some((i, n))
        })
        .collect();
    let i = match members.as_slice() {
        [] => {
            return Err(format(
                "the zip archive holds no .rexs or .rexsj file".into(),
            ))
        }
        [(i, _)] => *i,
        several => {
            let names: Vec<&str> = several.iter().map(|(_, n)| n.as_str()).collect();
            return Err(format(format!(
                "the zip archive holds {} REXS files ({}): unzip it and import the one you \
                 want",
                names.len(),
                names.join(", ")
            )));
        }
    };
    let mut file = archive
        .by_index(i)
        .map_err(|e| format(format!("zip member {i}: {e}")))?;
    let inner = format!(
        "{name}:{}",
        file.name().map(|n| n.to_string()).unwrap_or_default()
    );
    // Inflated no further than the limit of a REXS file (a small archive can hold gigabytes).
    let limit = crate::files::REXS_LIMIT;
    if file.size() > limit {
        return Err(format(format!(
            "zip member {inner}: {} bytes inflated, more than the {limit} bytes allowed",
            file.size()
        )));
    }
    let mut content = Vec::new();
    (&mut file)
        .take(limit + 1)
        .read_to_end(&mut content)
        .map_err(|e| format(format!("zip member {inner}: {e}")))?;
    if content.len() as u64 > limit {
        return Err(format(format!(
            "zip member {inner}: more than the {limit} bytes allowed when inflated"
        )));
    }
    parse_bytes(&content, &inner)
}

/// The model as text in the given encoding.
pub fn to_string(model: &Model, encoding: Encoding) -> String {
    match encoding {
        Encoding::Xml => xml::write(model),
        Encoding::Json => json::write(model),
    }
}

impl Model {
    /// The master model completed by load case `case` (REXS: a master model is calculable with
    /// one sub-model): each of the case's attributes replaces or joins the one of the same id on
    /// the master's component of the same id; the load spectrum itself is left out.
    pub fn with_load_case(&self, case: &LoadCase) -> Model {
        let mut model = Model {
            load_cases: Vec::new(),
            ..self.clone()
        };
        for varied in &case.components {
            let Some(c) = model.components.iter_mut().find(|c| c.id == varied.id) else {
                continue;
            };
            for a in &varied.attributes {
                match c.attributes.iter_mut().find(|x| x.id == a.id) {
                    Some(x) => *x = a.clone(),
                    None => c.attributes.push(a.clone()),
                }
            }
        }
        model
    }

    /// The component with this id.
    pub fn component(&self, id: u64) -> Option<&Component> {
        self.components.iter().find(|c| c.id == id)
    }

    /// Relations of a type in which component `id` has role `role`.
    pub fn relations_with<'a>(
        &'a self,
        kind: &'a str,
        id: u64,
        role: &'a str,
    ) -> impl Iterator<Item = &'a Relation> + 'a {
        self.relations
            .iter()
            .filter(move |r| r.kind == kind && r.refs.iter().any(|x| x.id == id && x.role == role))
    }

    /// In the relations of type `kind` where `id` has role `role`, the components in role
    /// `other`.
    pub fn related(&self, kind: &str, id: u64, role: &str, other: &str) -> Vec<&Component> {
        self.relations_with(kind, id, role)
            .flat_map(|r| r.refs.iter().filter(|x| x.role == other))
            .filter_map(|x| self.component(x.id))
            .collect()
    }
}

impl Component {
    /// The attribute with this id.
    pub fn attribute(&self, id: &str) -> Option<&Attribute> {
        self.attributes.iter().find(|a| a.id == id)
    }

    /// A label for messages: type, id and name.
    pub fn label(&self) -> String {
        if self.name.is_empty() {
            format!("{} [{}]", self.kind, self.id)
        } else {
            format!("{} [{}] \"{}\"", self.kind, self.id, self.name)
        }
    }
}
