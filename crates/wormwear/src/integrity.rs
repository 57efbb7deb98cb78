//! Content checksums of the files the program reads back (the life checkpoint, the bending
//! cache, the validation study's runs): a file that was changed after it was written (a flipped
//! digit that keeps the JSON valid, a scaled matrix) is detected on read instead of trusted.
//!
//! A sealed file is a JSON object whose first member `sha256` is the SHA-256 of the file's text
//! without that member: the compact JSON text as written (reformatting it counts as a change).
//! Files of earlier versions carry the member anywhere, over the compact text of the object
//! without it with the keys in serde_json's order (parsing and writing again gives the same
//! text); they open too.

use sha2::{Digest, Sha256};

/// Name of the checksum member.
pub const CHECKSUM: &str = "sha256";

/// Why a sealed file cannot be trusted.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum IntegrityError {
    #[error("not JSON: {0}")]
    Json(String),
    #[error("not a JSON object")]
    NotAnObject,
    #[error("no checksum (member `{CHECKSUM}`; written by an earlier version?)")]
    Missing,
    #[error("checksum mismatch: the content was changed after it was written")]
    Mismatch,
}

fn digest(value: &serde_json::Value) -> String {
    digest_text(&value.to_string())
}

/// The SHA-256 of a text, hex (a fingerprint of inputs).
pub fn digest_text(text: &str) -> String {
    let hash = Sha256::digest(text.as_bytes());
    hash.iter().map(|b| format!("{b:02x}")).collect()
}

/// A SHA-256 over text appended piece by piece (the records of a life as they are written).
#[derive(Debug, Clone, Default)]
pub struct RunningDigest(Sha256);

impl RunningDigest {
    /// Appends `text` to what the digest covers.
    pub fn update(&mut self, text: &str) {
        self.0.update(text.as_bytes());
    }

    /// The digest of everything appended so far, hex.
    pub fn hex(&self) -> String {
        self.0
            .clone()
            .finalize()
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect()
    }
}

/// The compact JSON text of `value` (an object) with its checksum member first. Written
/// straight from `value`, without an intermediate JSON tree (a life seals a checkpoint at
/// every state, issue 55).
pub fn seal<T: serde::Serialize>(value: &T) -> Result<String, IntegrityError> {
    let body = serde_json::to_string(value).map_err(|e| IntegrityError::Json(e.to_string()))?;
    let members = body
        .strip_prefix('{')
        .filter(|_| body.ends_with('}'))
        .ok_or(IntegrityError::NotAnObject)?;
    let separator = if members == "}" { "" } else { "," };
    Ok(format!(
        "{{\"{CHECKSUM}\":\"{}\"{separator}{members}",
        digest_text(&body)
    ))
}

/// The checksum and the text it covers of a text sealed by [`seal`] (its first member), or
/// None for another layout (an earlier version's).
fn sealed_first(text: &str) -> Option<(&str, String)> {
    let rest = text.strip_prefix(&format!("{{\"{CHECKSUM}\":\""))?;
    let (sum, members) = (rest.get(..64)?, rest.get(64..)?);
    let members = members
        .strip_prefix("\",")
        .or_else(|| members.strip_prefix('"').filter(|m| *m == "}"))?;
    Some((sum, format!("{{{members}")))
}

/// Parses a sealed text into `T` after checking its checksum (either layout).
pub fn open<T: serde::de::DeserializeOwned>(text: &str) -> Result<T, IntegrityError> {
    if let Some((sum, body)) = sealed_first(text) {
        if digest_text(&body) == sum {
            return serde_json::from_str(&body).map_err(|e| IntegrityError::Json(e.to_string()));
        }
    }
    let mut v: serde_json::Value =
        serde_json::from_str(text).map_err(|e| IntegrityError::Json(e.to_string()))?;
    let map = v.as_object_mut().ok_or(IntegrityError::NotAnObject)?;
    let stored = match map.remove(CHECKSUM) {
        Some(serde_json::Value::String(s)) => s,
        _ => return Err(IntegrityError::Missing),
    };
    if digest(&v) != stored {
        return Err(IntegrityError::Mismatch);
    }
    serde_json::from_value(v).map_err(|e| IntegrityError::Json(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, PartialEq, serde::Serialize, serde::Deserialize)]
    struct Doc {
        step: usize,
        values: Vec<f64>,
    }

    #[test]
    fn a_running_digest_is_the_digest_of_the_whole_text() {
        let mut running = RunningDigest::default();
        running.update("{\"step\":0}\n");
        let first = running.hex();
        running.update("{\"step\":1}\n");
        assert_eq!(first, digest_text("{\"step\":0}\n"));
        assert_eq!(running.hex(), digest_text("{\"step\":0}\n{\"step\":1}\n"));
        assert_ne!(running.hex(), digest_text("{\"step\":0}\n{\"step\":2}\n"));
    }

    #[test]
    fn a_sealed_document_opens_and_any_change_is_detected() {
        let doc = Doc {
            step: 12,
            values: vec![1.0 / 3.0, -2.5e-7, 6.02214076e23, 0.0],
        };
        let text = seal(&doc).unwrap();
        assert_eq!(open::<Doc>(&text).unwrap(), doc);
        // Reformatted (whitespace) but the same content: still valid.
        let pretty = serde_json::to_string_pretty(
            &serde_json::from_str::<serde_json::Value>(&text).unwrap(),
        )
        .unwrap();
        assert_eq!(open::<Doc>(&pretty).unwrap(), doc);
        // A flipped digit that keeps the JSON valid, a scaled value, a removed checksum.
        let flipped = text.replacen("12", "13", 1);
        assert_ne!(flipped, text);
        assert_eq!(open::<Doc>(&flipped), Err(IntegrityError::Mismatch));
        let scaled = text.replace("-2.5e-7", "-2.5e-5");
        assert_ne!(scaled, text);
        assert_eq!(open::<Doc>(&scaled), Err(IntegrityError::Mismatch));
        let plain = serde_json::to_string(&doc).unwrap();
        assert_eq!(open::<Doc>(&plain), Err(IntegrityError::Missing));
        assert!(matches!(
            open::<Doc>("{\"step\": "),
            Err(IntegrityError::Json(_))
        ));
    }

    /// Members out of serde_json's key order (the tree's order would differ from the text's).
    #[derive(Debug, PartialEq, serde::Serialize, serde::Deserialize)]
    struct Unsorted {
        zeta: f64,
        alpha: Vec<u32>,
    }

    #[test]
    fn a_seal_is_the_digest_of_the_text_as_written_and_earlier_seals_still_open() {
        let doc = Unsorted {
            zeta: 0.1,
            alpha: vec![3, 1],
        };
        let text = seal(&doc).unwrap();
        let plain = serde_json::to_string(&doc).unwrap();
        assert_eq!(
            text,
            format!("{{\"sha256\":\"{}\",{}", digest_text(&plain), &plain[1..])
        );
        assert_eq!(open::<Unsorted>(&text).unwrap(), doc);
        // The text as written is what is sealed: the members reordered is a change.
        let reordered = format!(
            "{{\"sha256\":\"{}\",\"alpha\":[3,1],\"zeta\":0.1}}",
            digest_text(&plain)
        );
        assert_eq!(open::<Unsorted>(&reordered), Err(IntegrityError::Mismatch));
        // An earlier version's seal: the checksum over the keys in serde_json's order, the
        // member among the others.
        let mut tree = serde_json::to_value(&doc).unwrap();
        let sum = digest(&tree);
        tree.as_object_mut()
            .unwrap()
            .insert(CHECKSUM.into(), serde_json::Value::String(sum));
        let earlier = tree.to_string();
        assert!(earlier.starts_with("{\"alpha\""), "{earlier}");
        assert_eq!(open::<Unsorted>(&earlier).unwrap(), doc);
        let changed = earlier.replace("0.1", "0.2");
        assert_eq!(open::<Unsorted>(&changed), Err(IntegrityError::Mismatch));
        // An empty object, and what is not an object.
        let empty = seal(&serde_json::json!({})).unwrap();
        assert_eq!(
            open::<serde_json::Value>(&empty).unwrap(),
            serde_json::json!({})
        );
        assert_eq!(seal(&[1, 2]), Err(IntegrityError::NotAnObject));
    }
}
