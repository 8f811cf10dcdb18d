//! Files the user named. Reading: only a regular file (after following
//! symlinks) is opened, so a FIFO, a directory or a device never blocks
//! the program in `open` or feeds it an endless stream. Writing: see
//! [`write_text`], which keeps the file what it was (link, permissions,
//! hard links, line endings).

mod style;
mod write;

pub use style::TextStyle;
pub use write::{WriteError, WriteMode, write_text};

use std::io::{self, Read};
use std::path::Path;

/// The largest key script or other text file read whole, 16 MiB (as a
/// scene file).
pub const MAX_TEXT_BYTES: u64 = 16 * 1024 * 1024;

/// What kind of non-regular file a path names, for the error message.
fn kind_of(meta: &std::fs::Metadata) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    let t = meta.file_type();
    if t.is_dir() {
        "a directory"
    } else if t.is_fifo() {
        "a FIFO (named pipe)"
    } else if t.is_socket() {
        "a socket"
    } else if t.is_char_device() || t.is_block_device() {
        "a device"
    } else {
        "not a regular file"
    }
}

/// The bytes of the regular file at `path`, at most `limit + 1` of them (so
/// the caller can tell a file over `limit` bytes).
///
/// # Errors
/// An [`io::ErrorKind::InvalidInput`] error naming the kind of file when
/// `path` is not a regular file; otherwise the error of `stat`, `open` or
/// `read`.
pub fn read_regular(path: &Path, limit: u64) -> io::Result<Vec<u8>> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "{} is {}, not a regular file",
                path.display(),
                kind_of(&meta)
            ),
        ));
    }
    let mut bytes = Vec::new();
    std::fs::File::open(path)?
        .take(limit.saturating_add(1))
        .read_to_end(&mut bytes)?;
    Ok(bytes)
}

/// The text of the regular file at `path` (see [`read_regular`]).
///
/// # Errors
/// As [`read_regular`], and [`io::ErrorKind::InvalidData`] when the file is
/// over `limit` bytes or is not UTF-8.
pub fn read_regular_text(path: &Path, limit: u64) -> io::Result<String> {
    let bytes = read_regular(path, limit)?;
    if bytes.len() as u64 > limit {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!("{} is larger than {limit} bytes", path.display()),
        ));
    }
    String::from_utf8(bytes).map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `nudge check FIFO` used to block forever in `open`.
    #[test]
    fn a_fifo_is_refused_before_it_is_opened() {
        let tmp = tempfile::Builder::new()
            .prefix("nudge-fifo-")
            .tempdir()
            .expect("temp dir");
        let dir = tmp.path().to_path_buf();
        let fifo = dir.join("scene.toml");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .expect("mkfifo (coreutils) is needed for this test");
        assert!(made.success());
        let err = read_regular(&fifo, 100).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
        assert!(
            err.to_string()
                .ends_with("is a FIFO (named pipe), not a regular file")
        );
        let err = read_regular(&dir, 100).unwrap_err();
        assert!(
            err.to_string()
                .ends_with("is a directory, not a regular file")
        );
    }

    #[test]
    fn a_regular_file_reads_up_to_one_past_the_limit() {
        let file = tempfile::Builder::new()
            .prefix("nudge-regular-")
            .tempfile()
            .expect("temp file");
        let path = file.path();
        std::fs::write(path, "0123456789").unwrap();
        assert_eq!(read_regular(path, 4).unwrap().len(), 5);
        assert_eq!(read_regular_text(path, 100).unwrap(), "0123456789");
        assert!(read_regular_text(path, 4).is_err());
    }
}
