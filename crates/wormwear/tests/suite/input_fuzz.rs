//! Fuzzing the gear-file parser and validator (issue 16): documents generated from the
//! examples' schema (every table and key of the five example files) and mutated one leaf or
//! table at a time — hostile numbers, wrong types, missing and unknown keys, tables replaced
//! by values and values by tables, deep nesting. Properties: nothing panics, and every
//! rejection names a field (a field error with its dotted name, or a parse error that quotes
//! the key). Tries a fixed number of documents (FUZZ_DOCUMENTS, default 2000), the same ones on
//! every machine and run, loaded in parallel, and prints how many were accepted and rejected.

use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use rayon::prelude::*;
use std::path::Path;
use toml::Value;
use wormwear::input::{self, InputError};

const EXAMPLES: [&str; 5] = [
    "gear-1x40-design.toml",
    "gear-1x40-case-a.toml",
    "gear-1x40-case-b.toml",
    "gear-1x40-case-c.toml",
    "gear-k-2x25.toml",
];

fn examples() -> Vec<toml::Table> {
    EXAMPLES
        .iter()
        .map(|name| {
            let path = Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../examples")
                .join(name);
            toml::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
        })
        .collect()
}

/// One step along a document: a key of a table or an index of an array.
#[derive(Debug, Clone, PartialEq)]
enum Step {
    Key(String),
    Index(usize),
}

/// Every path to a value of the document (tables, arrays and leaves), depth first.
fn paths(value: &Value, prefix: &mut Vec<Step>, out: &mut Vec<Vec<Step>>) {
    match value {
        Value::Table(t) => {
            for (k, v) in t {
                prefix.push(Step::Key(k.clone()));
                out.push(prefix.clone());
                paths(v, prefix, out);
                prefix.pop();
            }
        }
        Value::Array(a) => {
            for (i, v) in a.iter().enumerate() {
                prefix.push(Step::Index(i));
                out.push(prefix.clone());
                paths(v, prefix, out);
                prefix.pop();
            }
        }
        _ => {}
    }
}

fn at_mut<'a>(value: &'a mut Value, path: &[Step]) -> &'a mut Value {
    path.iter().fold(value, |v, s| match (s, v) {
        (Step::Key(k), Value::Table(t)) => t.get_mut(k).unwrap(),
        (Step::Index(i), Value::Array(a)) => &mut a[*i],
        _ => unreachable!("paths come from the document"),
    })
}

/// What a mutation does to the value at the chosen path.
#[derive(Debug, Clone)]
enum Mutation {
    Replace(Value),
    Scale(f64),
    Remove,
    AddUnknownKey,
    Nest(usize),
    /// A long list in place of the value: increasing numbers, or phase-like tables (the
    /// probe's 10^6 map cycles and 100 000 phases).
    LongList(usize, bool),
}

fn hostile_value() -> impl Strategy<Value = Value> {
    prop_oneof![
        Just(Value::Float(f64::NAN)),
        Just(Value::Float(f64::INFINITY)),
        Just(Value::Float(f64::NEG_INFINITY)),
        Just(Value::Float(-0.0)),
        Just(Value::Float(1e308)),
        Just(Value::Float(-1e308)),
        Just(Value::Float(1e-300)),
        Just(Value::Integer(0)),
        Just(Value::Integer(-1)),
        Just(Value::Integer(i64::MAX)),
        Just(Value::Integer(i64::MIN)),
        (-1e4f64..1e4).prop_map(Value::Float),
        Just(Value::String(String::new())),
        Just(Value::String("A".into())),
        Just(Value::String("x".repeat(10_000))),
        Just(Value::Boolean(true)),
        Just(Value::Array(vec![])),
        Just(Value::Array(vec![Value::Integer(1), Value::Integer(2)])),
        Just(Value::Array(vec![Value::Float(1.0); 100_000])),
        Just(Value::Table(toml::Table::new())),
    ]
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        6 => hostile_value().prop_map(Mutation::Replace),
        3 => prop_oneof![Just(-1.0), Just(0.0), Just(1e-6), Just(1e6), 0.2f64..5.0].prop_map(Mutation::Scale),
        2 => Just(Mutation::Remove),
        1 => Just(Mutation::AddUnknownKey),
        1 => (2usize..5000).prop_map(Mutation::Nest),
        1 => (prop_oneof![Just(300usize), Just(100_000usize)], any::<bool>())
            .prop_map(|(n, tables)| Mutation::LongList(n, tables)),
    ]
}

/// Applies `mutation` at `path`; returns the key that the rejection should name (the last key
/// on the path, or the unknown key added).
fn apply(doc: &mut Value, path: &[Step], mutation: &Mutation) -> String {
    let key = path
        .iter()
        .rev()
        .find_map(|s| match s {
            Step::Key(k) => Some(k.clone()),
            Step::Index(_) => None,
        })
        .unwrap_or_default();
    let (parent, last) = path.split_at(path.len() - 1);
    match mutation {
        Mutation::Replace(v) => *at_mut(doc, path) = v.clone(),
        Mutation::Scale(f) => {
            let target = at_mut(doc, path);
            match target {
                Value::Float(x) => *x *= f,
                Value::Integer(i) => *i = (*i as f64 * f).round() as i64,
                _ => {}
            }
        }
        Mutation::Remove => match (at_mut(doc, parent), &last[0]) {
            (Value::Table(t), Step::Key(k)) => {
                t.remove(k);
            }
            (Value::Array(a), Step::Index(i)) => {
                a.remove(*i);
            }
            _ => {}
        },
        Mutation::AddUnknownKey => {
            if let Value::Table(t) = at_mut(doc, parent) {
                t.insert("zz_unknown_key".into(), Value::Integer(1));
                return "zz_unknown_key".into();
            }
        }
        Mutation::LongList(n, tables) => {
            let items = (1..=*n).map(|k| match tables {
                false => Value::Float(k as f64),
                true => {
                    let mut t = toml::Table::new();
                    t.insert("kind".into(), Value::String("wear".into()));
                    t.insert("until_cycles".into(), Value::Float(k as f64));
                    Value::Table(t)
                }
            });
            *at_mut(doc, path) = Value::Array(items.collect());
            // Phase-like tables anywhere but in `phases` are refused for the key they replace
            // or for their own first key (either may be named).
            if *tables && key != "phases" {
                return format!("{key}|kind");
            }
        }
        Mutation::Nest(depth) => {
            let target = at_mut(doc, path);
            let mut v = target.clone();
            for _ in 0..*depth {
                v = Value::Array(vec![v]);
            }
            *target = v;
        }
    }
    key
}

/// Whether a rejection names a field: field errors each with a dotted field name, or a parse
/// error that quotes the key (the toml error echoes the offending line, or names a missing or
/// unknown field).
fn names_a_field(error: &InputError, key: &str) -> bool {
    match error {
        InputError::Invalid(fields) => {
            !fields.is_empty() && fields.iter().all(|f| !f.field.is_empty())
        }
        InputError::Syntax(message) => key.split('|').any(|k| message.contains(k)),
        InputError::Io { .. } => false,
    }
}

#[test]
fn mutated_gear_files_never_panic_and_every_rejection_names_a_field() {
    let count: usize = std::env::var("FUZZ_DOCUMENTS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2000);
    let start = std::time::Instant::now();
    // Chunks of documents, each from its own seeded generator, generated and loaded on the
    // pool; the outcomes come back in the chunks' order.
    let chunks = count.div_ceil(CHUNK);
    let outcomes: Vec<Outcome> = (0..chunks)
        .into_par_iter()
        .flat_map_iter(|c| {
            let documents = mutated_documents(c, CHUNK.min(count - c * CHUNK));
            documents
                .into_iter()
                .map(|(text, keys)| load_outcome(&text, &keys))
                .collect::<Vec<_>>()
        })
        .collect();
    let accepted = outcomes
        .iter()
        .filter(|o| matches!(o, Outcome::Accepted))
        .count();
    let unnamed: Vec<&String> = outcomes
        .iter()
        .filter_map(|o| match o {
            Outcome::Unnamed(m) => Some(m),
            _ => None,
        })
        .collect();
    eprintln!(
        "input fuzz: {} documents in {:.1} s: {accepted} accepted, {} rejected, {} rejections \
         without a field",
        outcomes.len(),
        start.elapsed().as_secs_f64(),
        outcomes.len() - accepted,
        unnamed.len()
    );
    assert!(
        outcomes.len() >= count / 2,
        "only {} documents",
        outcomes.len()
    );
    assert!(
        accepted > 0 && accepted < outcomes.len(),
        "{accepted} accepted"
    );
    let unnamed: Vec<&str> = unnamed.iter().map(|m| m.as_str()).collect();
    assert!(unnamed.is_empty(), "{}", unnamed.join("\n"));
}

/// What loading one mutated document gave.
enum Outcome {
    Accepted,
    Named,
    /// A rejection that names none of the mutated keys: its keys and message.
    Unnamed(String),
}

/// Loads `text`; panics (naming the document) if the loader panics.
fn load_outcome(text: &str, keys: &[String]) -> Outcome {
    match std::panic::catch_unwind(|| input::load_from_str(text)) {
        Err(_) => panic!("the loader panicked on:\n{text}"),
        Ok(Ok(_)) => Outcome::Accepted,
        Ok(Err(e)) if keys.iter().any(|k| names_a_field(&e, k)) || names_a_field(&e, "\u{1}") => {
            Outcome::Named
        }
        Ok(Err(e)) => Outcome::Unnamed(format!("keys {keys:?}: {}", cut(&e.to_string()))),
    }
}

/// Documents per generator of the fuzz test.
const CHUNK: usize = 50;

/// `count` tries at a mutated document from the generator seeded with `chunk` (the same
/// sequence on every run: a failure prints its document): an example with one or two
/// mutations, the first on a path of the example, a second (on the mutated document) from the
/// same strategy; as TOML text with the mutated keys. Tries whose document does not serialise
/// are skipped.
fn mutated_documents(chunk: usize, count: usize) -> Vec<(String, Vec<String>)> {
    let bases: Vec<Value> = examples().into_iter().map(Value::Table).collect();
    let all_paths: Vec<Vec<Vec<Step>>> = bases
        .iter()
        .map(|b| {
            let mut out = Vec::new();
            paths(b, &mut Vec::new(), &mut out);
            out
        })
        .collect();
    let case = (
        0..bases.len(),
        any::<prop::sample::Index>(),
        mutation(),
        1usize..3,
    );
    let mut seed = [0u8; 32];
    seed[..8].copy_from_slice(&(chunk as u64).to_le_bytes());
    let rng = TestRng::from_seed(RngAlgorithm::ChaCha, &seed);
    let mut runner = TestRunner::new_with_rng(Config::default(), rng);
    let mut documents = Vec::with_capacity(count);
    for _ in 0..count {
        let (which, pick, first, mutations) = case.new_tree(&mut runner).unwrap().current();
        let mut doc = bases[which].clone();
        let mut keys = Vec::new();
        let mut mutation = first;
        for k in 0..mutations {
            let mut found = Vec::new();
            paths(&doc, &mut Vec::new(), &mut found);
            let candidates = if k == 0 { &all_paths[which] } else { &found };
            if candidates.is_empty() {
                break;
            }
            let path = candidates[pick.index(candidates.len())].clone();
            keys.push(apply(&mut doc, &path, &mutation));
            mutation = Mutation::Scale(0.5);
        }
        if let Ok(text) = toml::to_string(&doc) {
            documents.push((text, keys));
        }
    }
    documents
}

fn cut(s: &str) -> String {
    s.chars().take(300).collect()
}

/// Nesting deeper than the parser's recursion limit is named with its line.
#[test]
fn deep_nesting_names_its_line() {
    let base = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/gear-1x40-design.toml"),
    )
    .unwrap();
    let line = base.lines().count() + 2;
    for tail in [
        format!("\n[{}]\n", vec!["a"; 5000].join(".")),
        format!("\n{} = 1\n", vec!["a"; 20_000].join(".")),
        format!("\nx = {}{}\n", "[".repeat(5000), "]".repeat(5000)),
    ] {
        let e = input::load_from_str(&format!("{base}{tail}")).unwrap_err();
        let m = e.to_string();
        assert!(m.contains(&format!("line {line}")), "{}", cut(&m));
        assert!(m.len() < 2000, "{} characters", m.len());
    }
}
