//! Build script: a digest of the library's sources, `WORMWEAR_SOURCE_STAMP`, so that results
//! kept for reuse (a life's checkpoint, a sweep's variants, the validation study's runs) are
//! reused only by the program that computed them (`wormwear::PROGRAM`).
//!
//! The digest is FNV-1a (64 bit) over every file under `src/` but hidden ones, in the order
//! of their paths, each as its path relative to `src/` (with `/`), a zero byte, its bytes and a
//! zero byte: the same sources give the same stamp on every machine and toolchain.

use std::path::{Path, PathBuf};

fn files_under(dir: &Path, out: &mut Vec<PathBuf>) -> std::io::Result<()> {
    for entry in std::fs::read_dir(dir)? {
        let path = entry?.path();
        // (Hidden files, such as an editor's swap files, are no part of the program.)
        if path
            .file_name()
            .is_some_and(|n| n.to_string_lossy().starts_with('.'))
        {
            continue;
        }
        if path.is_dir() {
            files_under(&path, out)?;
        } else {
            out.push(path);
        }
    }
    Ok(())
}

fn main() {
    const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
    const PRIME: u64 = 0x0000_0100_0000_01b3;
    let root = Path::new("src");
    let mut files = Vec::new();
    files_under(root, &mut files).expect("the library's sources (src/) can be listed");
    let mut named: Vec<(String, PathBuf)> = files
        .into_iter()
        .map(|p| {
            let relative = p.strip_prefix(root).unwrap_or(&p);
            let name: Vec<String> = relative
                .components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect();
            (name.join("/"), p)
        })
        .collect();
    named.sort();
    let mut hash = OFFSET;
    let mut feed = |bytes: &[u8]| {
        for &b in bytes {
            hash ^= u64::from(b);
            hash = hash.wrapping_mul(PRIME);
        }
    };
    for (name, path) in &named {
        let bytes = std::fs::read(path).expect("a source file can be read");
        feed(name.as_bytes());
        feed(&[0]);
        feed(&bytes);
        feed(&[0]);
    }
    println!("cargo:rustc-env=WORMWEAR_SOURCE_STAMP={hash:016x}");
    println!("cargo:rerun-if-changed=src");
    println!("cargo:rerun-if-changed=build.rs");
}
