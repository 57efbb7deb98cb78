//! Content checksums of the files the program reads back (the life checkpoint, the bending
//! cache, the validation study's runs): a file that was changed after it was written (a flipped
//! digit that keeps the JSON valid, a scaled matrix) is detected on read instead of trusted.
//!
//! A sealed file is a JSON object with a member `sha256`: the SHA-256 of the compact JSON text
//! of the object without that member (keys in serde_json's order, numbers as serde_json writes
//! them, so parsing and writing again gives the same text).

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

/// The JSON text of `value` (an object) with its checksum member added.
pub fn seal<T: serde::Serialize>(value: &T) -> Result<String, IntegrityError> {
    let mut v = serde_json::to_value(value).map_err(|e| IntegrityError::Json(e.to_string()))?;
    let sum = digest(&v);
    v.as_object_mut()
        .ok_or(IntegrityError::NotAnObject)?
        .insert(CHECKSUM.to_string(), serde_json::Value::String(sum));
    Ok(v.to_string())
}

/// Parses a sealed text into `T` after checking its checksum.
pub fn open<T: serde::de::DeserializeOwned>(text: &str) -> Result<T, IntegrityError> {
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
}
