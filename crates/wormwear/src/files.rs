//! Bounded reads of the files the program is given or reads back: a gear, sweep or REXS file,
//! a cache entry, a checkpoint. Only a regular file is read (a FIFO, a device or a directory
//! is refused before it is opened: opening a FIFO blocks, a device can be endless), and at most
//! a stated number of bytes, so a wrong path fails at once with a message instead of filling the
//! memory or hanging.

use std::io::{Error, ErrorKind, Read};
use std::path::Path;

/// The most bytes a gear file or a sweep file may have (a gear file is a few kB).
pub const INPUT_LIMIT: u64 = 16 << 20;
/// The most bytes a REXS file, or a member inflated from a REXS zip, may have.
pub const REXS_LIMIT: u64 = 256 << 20;
/// The most bytes a file the program wrote and reads back may have (a cache entry, a
/// checkpoint, the records of a life, a run of the validation study).
pub const OWN_FILE_LIMIT: u64 = 4 << 30;

/// The bytes of `path`, a regular file of at most `limit` bytes. A missing file is the
/// `NotFound` error of the file system; anything else that is not a regular file, or a file
/// over the limit, an `InvalidInput` error that says so.
pub fn read_bytes(path: &Path, limit: u64) -> std::io::Result<Vec<u8>> {
    let meta = std::fs::metadata(path)?;
    if !meta.file_type().is_file() {
        return Err(Error::new(
            ErrorKind::InvalidInput,
            format!("not a regular file ({}): refused", kind_of(&meta)),
        ));
    }
    let too_large = |size: u64| {
        Error::new(
            ErrorKind::InvalidInput,
            format!("{size} bytes, more than the {limit} bytes allowed for this file"),
        )
    };
    if meta.len() > limit {
        return Err(too_large(meta.len()));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    // A file that grows while it is read stops at the limit too.
    std::fs::File::open(path)?
        .take(limit + 1)
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(too_large(bytes.len() as u64));
    }
    Ok(bytes)
}

/// [`read_bytes`] as UTF-8 text.
pub fn read_text(path: &Path, limit: u64) -> std::io::Result<String> {
    String::from_utf8(read_bytes(path, limit)?)
        .map_err(|e| Error::new(ErrorKind::InvalidData, format!("not UTF-8 text ({e})")))
}

/// What is at `path` when it is neither absent nor a regular file (nor a link to one), in
/// words: a directory, a device, a FIFO, a socket. A dangling link reads as absent.
pub fn not_a_regular_file(path: &Path) -> Option<&'static str> {
    let meta = std::fs::metadata(path).ok()?;
    (!meta.file_type().is_file()).then(|| kind_of(&meta))
}

/// A run's results read back (summary.json, its tables), bytes.
pub const RESULT_LIMIT: u64 = 256 << 20;

/// What a non-regular file is, in words.
fn kind_of(meta: &std::fs::Metadata) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = meta.file_type();
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_char_device() || t.is_block_device() {
            return "a device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if meta.is_dir() {
        "a directory"
    } else {
        "not a regular file"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_regular_files_within_the_limit_are_read() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("gear.toml");
        std::fs::write(&file, "x = 1\n").unwrap();
        assert_eq!(read_text(&file, 6).unwrap(), "x = 1\n");
        let err = read_text(&file, 5).unwrap_err();
        assert_eq!(err.kind(), ErrorKind::InvalidInput);
        assert!(
            err.to_string().contains("6 bytes, more than the 5"),
            "{err}"
        );
        let err = read_text(dir.path(), 5).unwrap_err();
        assert!(err.to_string().contains("a directory"), "{err}");
        assert_eq!(
            read_text(&dir.path().join("missing"), 5)
                .unwrap_err()
                .kind(),
            ErrorKind::NotFound
        );
        #[cfg(unix)]
        {
            // A device is refused before a byte is read (reading /dev/zero never ends).
            let err = read_text(Path::new("/dev/zero"), INPUT_LIMIT).unwrap_err();
            assert!(err.to_string().contains("a device"), "{err}");
            // A FIFO is refused without being opened (opening one blocks until a writer comes).
            let fifo = dir.path().join("fifo");
            let made = std::process::Command::new("mkfifo").arg(&fifo).status();
            if made.is_ok_and(|s| s.success()) {
                let err = read_text(&fifo, INPUT_LIMIT).unwrap_err();
                assert!(err.to_string().contains("a FIFO"), "{err}");
            }
            // A symbolic link to a regular file is read.
            let link = dir.path().join("link.toml");
            std::os::unix::fs::symlink(&file, &link).unwrap();
            assert_eq!(read_text(&link, 6).unwrap(), "x = 1\n");
        }
    }
}
