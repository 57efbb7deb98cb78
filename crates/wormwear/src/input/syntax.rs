//! Reading a gear file's TOML text: every unknown key and every missing key or table at once,
//! parse errors with their long lines cut and, for a nesting too deep to place, its line.

use super::{GearFile, InputError};

/// The most unknown keys [`parse_gear_file`] collects before it reports them.
const MAX_UNKNOWN_KEYS: usize = 64;

/// The gear file's tables, or every unknown key at once: the TOML reader stops at the first
/// unknown key, so each one (a `key = value` line) is commented out in a copy of the text,
/// which keeps the line numbers, and the text read again; the errors are reported together,
/// with the first error of another kind (a missing key, a wrong type) if one follows.
pub(super) fn parse_gear_file(text: &str) -> Result<GearFile, InputError> {
    let first = match toml::from_str::<GearFile>(text) {
        Ok(file) => return Ok(file),
        Err(e) => e,
    };
    let mut errors = vec![syntax_error(&first, text).to_string()];
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let mut current = first;
    while errors.len() < MAX_UNKNOWN_KEYS && current.message().starts_with("unknown field") {
        let joined = lines.join("\n");
        let Some(line) = current
            .span()
            .map(|s| joined[..s.start].matches('\n').count())
        else {
            break;
        };
        // Only a one-line `key = value`: a table header or a value over several lines would
        // leave a text whose next error is not the user's.
        let key_line = lines.get(line).is_some_and(|l| {
            let t = l.trim_start();
            !t.starts_with('[') && t.contains('=') && !t.trim_end().ends_with('[')
        });
        if !key_line {
            break;
        }
        lines[line] = format!("# {}", lines[line]);
        let joined = lines.join("\n");
        match toml::from_str::<GearFile>(&joined) {
            Ok(_) => break,
            Err(e) => {
                errors.push(syntax_error(&e, &joined).to_string());
                current = e;
            }
        }
    }
    if current.message().starts_with("missing field") {
        let missing = missing_keys(&lines.join("\n"));
        if !missing.is_empty() {
            errors.pop();
            errors.extend(missing);
        }
    }
    Err(InputError::Syntax(errors.join("\n")))
}

/// The required tables of a gear file and the type each is read as.
type TableCheck = fn(toml::Value) -> Result<(), toml::de::Error>;

fn table_check<T: serde::de::DeserializeOwned>(v: toml::Value) -> Result<(), toml::de::Error> {
    T::deserialize(v).map(|_| ())
}

const REQUIRED_TABLES: &[(&str, bool, TableCheck)] = &[
    ("worm", true, table_check::<super::schema::ThreadSpec>),
    ("hob", true, table_check::<super::schema::ThreadSpec>),
    ("cutting", true, table_check::<super::schema::SettingSpec>),
    ("wheel", true, table_check::<super::schema::WheelSpec>),
    (
        "operating",
        true,
        table_check::<super::schema::OperatingSpec>,
    ),
    (
        "conditions",
        true,
        table_check::<super::schema::ConditionsSpec>,
    ),
    (
        "materials.worm",
        false,
        table_check::<super::schema::MaterialSpec>,
    ),
    (
        "materials.wheel",
        false,
        table_check::<super::schema::MaterialSpec>,
    ),
    ("wear", false, table_check::<super::schema::WearSpec>),
];

/// Every required key and table the gear file's text leaves out, each with the line of its
/// table's header: each table read alone, a missing key given a stand-in value (of the first
/// type it takes) and the table read again, until nothing more is missing. Empty when the text
/// is not TOML or a key is missing from a table inside a table (the reader's message then).
fn missing_keys(text: &str) -> Vec<String> {
    let Ok(root) = text.parse::<toml::Table>() else {
        return Vec::new();
    };
    let mut out = Vec::new();
    // A load spectrum stands for [conditions]; each of its bins needs its own keys.
    let spectrum = root.get("duty_cycle").and_then(|v| v.as_array());
    for (k, bin) in spectrum.into_iter().flatten().enumerate() {
        let Err(e) = table_check::<super::schema::DutyBinSpec>(bin.clone()) else {
            continue;
        };
        if let Some(key) = e.message().strip_prefix("missing field `") {
            let key = key.split('`').next().unwrap_or_default();
            out.push(format!("duty_cycle[{}] is missing the key `{key}`", k + 1));
        }
    }
    for &(path, required, check) in REQUIRED_TABLES {
        let required = required && !(path == "conditions" && spectrum.is_some());
        let table = path
            .split('.')
            .try_fold(&root, |t, part| t.get(part)?.as_table());
        let Some(table) = table else {
            if required {
                out.push(format!("the file has no [{path}] table"));
            }
            continue;
        };
        let line = text
            .lines()
            .position(|l| l.trim_start().starts_with(&format!("[{path}]")))
            .map_or(String::new(), |k| format!("line {}: ", k + 1));
        let mut table = table.clone();
        while let Err(e) = check(toml::Value::Table(table.clone())) {
            let Some(key) = e
                .message()
                .strip_prefix("missing field `")
                .and_then(|m| m.split('`').next())
                .map(String::from)
            else {
                break;
            };
            out.push(format!("{line}[{path}] is missing the key `{key}`"));
            let stand_in = [
                toml::Value::Float(1.0),
                toml::Value::Integer(1),
                toml::Value::String(String::new()),
                toml::Value::Array(Vec::new()),
            ]
            .into_iter()
            .find(|v| {
                let mut t = table.clone();
                t.insert(key.clone(), v.clone());
                check(toml::Value::Table(t)).err().is_none_or(|e| {
                    !e.message().contains(&format!("`{key}`"))
                        && !e.message().starts_with("invalid type")
                })
            });
            match stand_in {
                Some(v) if !table.contains_key(&key) => {
                    table.insert(key, v);
                }
                // Not a key of this table itself but of a table inside it: the reader's own
                // message, which shows the place, says it better.
                _ => return Vec::new(),
            }
        }
    }
    out
}

/// A parse error of `text` as an input error, its long lines cut.
pub(super) fn syntax_error(e: &toml::de::Error, text: &str) -> InputError {
    let message = cut_long_lines(&e.to_string());
    // An error without a place (the parser's recursion limit on a table header of
    // thousands of keys): name the most deeply nested line.
    InputError::Syntax(match (e.span(), deepest_line(text)) {
        (None, Some((line, depth))) if depth > 8 => format!(
            "{message}: line {line} nests {depth} levels deep (table headers, dotted \
             keys, arrays or inline tables); a gear file needs at most 3"
        ),
        _ => message,
    })
}

/// The line (1-based) of the deepest nesting of a TOML text and its depth: keys of a table
/// header or of a dotted key, or brackets and braces of a value (quoted text and comments
/// skipped).
fn deepest_line(text: &str) -> Option<(usize, usize)> {
    let mut best: Option<(usize, usize)> = None;
    let mut depth = 0usize;
    for (k, line) in text.lines().enumerate() {
        let trimmed = line.trim_start();
        let mut deepest = depth;
        if depth == 0 && trimmed.starts_with('[') {
            deepest = trimmed
                .split(']')
                .next()
                .map_or(1, |h| h.matches('.').count() + 1);
        } else {
            let mut quote: Option<char> = None;
            // The dotted parts of a key (a line outside a value, up to its '=').
            let mut key_parts = (depth == 0).then_some(1usize);
            for c in line.chars() {
                match (quote, c) {
                    (Some(q), c) if c == q => quote = None,
                    (Some(_), _) => {}
                    (None, '"' | '\'') => quote = Some(c),
                    (None, '#') => break,
                    (None, '.') if key_parts.is_some() => {
                        key_parts = key_parts.map(|k| k + 1);
                        deepest = deepest.max(key_parts.unwrap_or(0));
                    }
                    (None, '=') if key_parts.is_some() => key_parts = None,
                    (None, '[' | '{') => {
                        depth += 1;
                        deepest = deepest.max(depth);
                    }
                    (None, ']' | '}') => depth = depth.saturating_sub(1),
                    _ => {}
                }
            }
        }
        if best.is_none_or(|b| deepest > b.1) {
            best = Some((k + 1, deepest));
        }
    }
    best
}

/// A message with every line longer than 400 characters cut there (a parse error echoes the
/// offending source line, which may be a 100 000-element array).
fn cut_long_lines(message: &str) -> String {
    const LONGEST: usize = 400;
    message
        .lines()
        .map(|line| {
            let count = line.chars().count();
            if count > LONGEST {
                let head: String = line.chars().take(LONGEST).collect();
                format!("{head}... ({count} characters)")
            } else {
                line.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}
