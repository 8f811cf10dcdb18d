//! Writing a file the user named so that it stays the file it was: the
//! text is written atomically (a temporary file beside it, flushed, then
//! renamed over it; the temporary file is created exclusively, never
//! through a link another user planted, and readable only by the user
//! until it takes the original's mode), but
//!
//! - a symlink is followed and its target written (the link stays a link);
//! - the original's permission bits are kept, and its owner and group
//!   where the user may set them;
//! - a read-only file is refused unless the write is forced (as vim's
//!   `:w!`), and then stays read-only;
//! - a file with other hard links is written in place (truncated and
//!   rewritten, then flushed), so every name sees the new text: a rename
//!   would leave the other names with the old text. This one case is not
//!   atomic;
//! - a directory, FIFO, socket or device is refused, never replaced;
//! - a UTF-8 byte-order mark and CRLF line endings found in the original
//!   are kept.

use std::fs::{self, File, Metadata};
use std::io::{self, Write};
use std::os::unix::fs::{MetadataExt, PermissionsExt};
use std::path::{Path, PathBuf};

/// Whether a write may replace a read-only file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WriteMode {
    /// Refuse a read-only file.
    Normal,
    /// Write a read-only file anyway (it stays read-only).
    Force,
}

/// Why a file was not written. The file is left as it was.
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    #[error("{} is read-only", path.display())]
    ReadOnly { path: PathBuf },
    #[error("{} is {kind}, not a regular file", path.display())]
    NotRegular { path: PathBuf, kind: &'static str },
    #[error("{}: {source}", path.display())]
    Io { path: PathBuf, source: io::Error },
    /// A file with other hard links is rewritten in place (see
    /// [`write_text`]), so a failure after it was truncated leaves it
    /// incomplete.
    #[error(
        "{}: {source}, part way through rewriting it in place (it has other hard links): it may be incomplete; save again once that is fixed",
        path.display()
    )]
    Partial { path: PathBuf, source: io::Error },
}

/// Symlinks followed this many times at most (as the kernel's ELOOP).
const MAX_LINKS: usize = 40;

/// The file `path` names once every symlink is followed (it may not exist
/// yet: a dangling link names the file it will create).
fn resolve(path: &Path) -> Result<PathBuf, WriteError> {
    let mut p = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        match fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let to = fs::read_link(&p).map_err(|source| WriteError::Io {
                    path: p.clone(),
                    source,
                })?;
                p = match p.parent() {
                    Some(dir) if to.is_relative() => dir.join(to),
                    _ => to,
                };
            }
            _ => return Ok(p),
        }
    }
    Err(WriteError::Io {
        path: path.to_path_buf(),
        source: io::Error::other("too many levels of symbolic links"),
    })
}

/// Whether the existing file at `path` may be written: it has a write
/// permission bit (as vim judges it, so a 0444 file is read-only for root
/// too) and the user may write it.
fn writable(path: &Path, meta: &Metadata) -> bool {
    !meta.permissions().readonly() && rustix::fs::access(path, rustix::fs::Access::WRITE_OK).is_ok()
}

/// Write `text` to the file `path` names (see the module documentation).
///
/// # Errors
/// [`WriteError::ReadOnly`] for a read-only file written with
/// [`WriteMode::Normal`], [`WriteError::NotRegular`] for anything but a
/// regular file, [`WriteError::Io`] for the I/O error otherwise. The file
/// is then as it was (an in-place write of a hard-linked file may fail
/// part way: that is
/// [`WriteError::Partial`]).
pub fn write_text(path: &Path, text: &str, mode: WriteMode) -> Result<(), WriteError> {
    let target = resolve(path)?;
    let io = |source: io::Error| WriteError::Io {
        path: target.clone(),
        source,
    };
    let meta = match fs::metadata(&target) {
        Ok(m) => Some(m),
        Err(e) if e.kind() == io::ErrorKind::NotFound => None,
        Err(e) => return Err(io(e)),
    };
    let Some(meta) = meta else {
        return replace(&target, text.as_bytes(), None);
    };
    if !meta.is_file() {
        return Err(WriteError::NotRegular {
            path: target,
            kind: super::kind_of(&meta),
        });
    }
    if !writable(&target, &meta) && mode == WriteMode::Normal {
        return Err(WriteError::ReadOnly { path: target });
    }
    let original = super::read_regular(&target, super::MAX_TEXT_BYTES).map_err(io)?;
    let text = super::TextStyle::of(&original).apply(text);
    if meta.nlink() > 1 {
        in_place(&target, text.as_bytes(), &meta)
    } else {
        replace(&target, text.as_bytes(), Some(&meta))
    }
}

/// Temporary names tried beside the target before giving up (others may
/// be left by a crash, or planted).
const TEMP_TRIES: u32 = 100;

/// A new temporary file beside `target`, created exclusively (never
/// through a link or over an existing file) and private (0600) until its
/// mode is set, so a private scene's text is never readable by others.
fn create_temp(target: &Path, private: bool) -> io::Result<(File, PathBuf)> {
    use std::os::unix::fs::OpenOptionsExt;
    let name = target
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let pid = std::process::id();
    let mut last = None;
    for k in 0..TEMP_TRIES {
        let tmp = target.with_file_name(format!(".{name}.nudge-{pid}-{k}.tmp"));
        match fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .mode(if private { 0o600 } else { 0o666 })
            .open(&tmp)
        {
            Ok(f) => return Ok((f, tmp)),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => last = Some(e),
            Err(e) => return Err(e),
        }
    }
    Err(last.unwrap_or_else(|| io::Error::other("no temporary file name is free")))
}

/// Give `f` the owner and group of `original` where the user may: both,
/// else the group alone (a user may give a file any group they are in),
/// else neither (`EPERM` is not an error: the file is then the user's).
fn keep_owner(f: &File, original: &Metadata) -> io::Result<()> {
    use std::os::unix::fs::fchown;
    let denied = |r: io::Result<()>| match r {
        Err(e) if e.kind() == io::ErrorKind::PermissionDenied => Ok(false),
        other => other.map(|()| true),
    };
    let now = f.metadata()?;
    if (now.uid(), now.gid()) == (original.uid(), original.gid()) {
        return Ok(());
    }
    if !denied(fchown(f, Some(original.uid()), Some(original.gid())))? {
        denied(fchown(f, None, Some(original.gid())))?;
    }
    Ok(())
}

/// Write a temporary file beside `target` with `original`'s permissions
/// and owner, then rename it over `target`.
fn replace(target: &Path, bytes: &[u8], original: Option<&Metadata>) -> Result<(), WriteError> {
    let io = |source: io::Error| WriteError::Io {
        path: target.to_path_buf(),
        source,
    };
    let (mut f, tmp) = create_temp(target, original.is_some()).map_err(io)?;
    let result = (|| {
        f.write_all(bytes)?;
        if let Some(m) = original {
            // Owner first: changing it may clear set-id bits the mode keeps.
            keep_owner(&f, m)?;
            f.set_permissions(fs::Permissions::from_mode(m.mode() & 0o7777))?;
        }
        f.sync_all()?;
        drop(f);
        fs::rename(&tmp, target)?;
        if let Some(dir) = target.parent().filter(|d| !d.as_os_str().is_empty()) {
            // The rename itself reaches the disk with the directory.
            let _ = File::open(dir).and_then(|d| d.sync_all());
        }
        Ok(())
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result.map_err(io)
}

/// Truncate and rewrite `target` through its own inode (every hard link
/// sees it); a read-only file (forced) is made writable for the write and
/// read-only again after. An error once the file is truncated is
/// [`WriteError::Partial`].
fn in_place(target: &Path, bytes: &[u8], meta: &Metadata) -> Result<(), WriteError> {
    let io = |source: io::Error| WriteError::Io {
        path: target.to_path_buf(),
        source,
    };
    let mode = meta.mode() & 0o7777;
    let restore = mode & 0o200 == 0;
    if restore {
        fs::set_permissions(target, fs::Permissions::from_mode(mode | 0o200)).map_err(io)?;
    }
    let result = fs::OpenOptions::new()
        .write(true)
        .truncate(true)
        .open(target)
        .map_err(io)
        .and_then(|mut f| {
            f.write_all(bytes)
                .and_then(|()| f.sync_all())
                .map_err(|source| WriteError::Partial {
                    path: target.to_path_buf(),
                    source,
                })
        });
    if restore {
        let back = fs::set_permissions(target, fs::Permissions::from_mode(mode));
        result?;
        back.map_err(io)?;
        return Ok(());
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::fs::FileTypeExt;

    /// A fresh directory for one test, deleted when dropped.
    fn dir(name: &str) -> tempfile::TempDir {
        tempfile::Builder::new()
            .prefix(&format!("nudge-write-{name}-"))
            .tempdir()
            .expect("temp dir")
    }

    fn mode(p: &Path) -> u32 {
        fs::metadata(p).expect("stat").permissions().mode() & 0o7777
    }

    #[test]
    fn a_private_file_stays_private() {
        let d = dir("private");
        let f = d.path().join("s.toml");
        fs::write(&f, "a = 1\n").unwrap();
        fs::set_permissions(&f, fs::Permissions::from_mode(0o600)).unwrap();
        write_text(&f, "a = 2\n", WriteMode::Normal).expect("written");
        assert_eq!(fs::read_to_string(&f).unwrap(), "a = 2\n");
        assert_eq!(mode(&f), 0o600);
    }

    /// A link (or any file) already at the temporary name is neither
    /// followed nor replaced, and no temporary file is left behind.
    #[test]
    fn a_file_planted_at_the_temporary_name_is_left_alone() {
        let d = dir("planted");
        let f = d.path().join("s.toml");
        let victim = d.path().join("victim.txt");
        fs::write(&f, "a = 1\n").unwrap();
        fs::write(&victim, "precious\n").unwrap();
        let planted = d
            .path()
            .join(format!(".s.toml.nudge-{}-0.tmp", std::process::id()));
        std::os::unix::fs::symlink("victim.txt", &planted).unwrap();
        write_text(&f, "a = 2\n", WriteMode::Normal).expect("written");
        assert_eq!(fs::read_to_string(&f).unwrap(), "a = 2\n");
        assert!(!fs::symlink_metadata(&f).unwrap().file_type().is_symlink());
        assert_eq!(fs::read_to_string(&victim).unwrap(), "precious\n");
        assert!(
            fs::symlink_metadata(&planted)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        let mut names: Vec<String> = fs::read_dir(d.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        let expected = [
            planted.file_name().unwrap().to_string_lossy().into_owned(),
            "s.toml".to_string(),
            "victim.txt".to_string(),
        ];
        assert_eq!(names, expected);
    }

    /// The owner and group are kept where the user may set them (root
    /// may); where not, the save still succeeds and the file is the user's.
    #[test]
    fn the_owner_is_kept_where_permitted() {
        let d = dir("owner");
        let f = d.path().join("s.toml");
        fs::write(&f, "a = 1\n").unwrap();
        let me = fs::metadata(&f).unwrap();
        let (uid, gid) = (me.uid() + 4321, me.gid() + 4321);
        match std::os::unix::fs::chown(&f, Some(uid), Some(gid)) {
            Ok(()) => {
                fs::set_permissions(&f, fs::Permissions::from_mode(0o640)).unwrap();
                write_text(&f, "a = 2\n", WriteMode::Normal).expect("written");
                let after = fs::metadata(&f).unwrap();
                assert_eq!((after.uid(), after.gid()), (uid, gid));
                assert_eq!(mode(&f), 0o640);
            }
            Err(e) => {
                assert_eq!(e.kind(), io::ErrorKind::PermissionDenied, "{e}");
                write_text(&f, "a = 2\n", WriteMode::Normal).expect("written");
                let after = fs::metadata(&f).unwrap();
                assert_eq!((after.uid(), after.gid()), (me.uid(), me.gid()));
            }
        }
        assert_eq!(fs::read_to_string(&f).unwrap(), "a = 2\n");
    }

    #[test]
    fn a_read_only_file_is_written_only_when_forced_and_stays_read_only() {
        let d = dir("readonly");
        let f = d.path().join("s.toml");
        fs::write(&f, "a = 1\n").unwrap();
        fs::set_permissions(&f, fs::Permissions::from_mode(0o444)).unwrap();
        match write_text(&f, "a = 2\n", WriteMode::Normal) {
            Err(WriteError::ReadOnly { path }) => assert_eq!(path, f),
            other => panic!("{other:?}"),
        }
        assert_eq!(fs::read_to_string(&f).unwrap(), "a = 1\n");
        write_text(&f, "a = 2\n", WriteMode::Force).expect("forced");
        assert_eq!(fs::read_to_string(&f).unwrap(), "a = 2\n");
        assert_eq!(mode(&f), 0o444);
    }

    #[test]
    fn a_symlink_stays_a_link_and_its_target_is_written() {
        let d = dir("symlink");
        let real = d.path().join("real.toml");
        let link = d.path().join("link.toml");
        fs::write(&real, "a = 1\n").unwrap();
        std::os::unix::fs::symlink("real.toml", &link).unwrap();
        write_text(&link, "a = 2\n", WriteMode::Normal).expect("written");
        assert!(
            fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(fs::read_to_string(&real).unwrap(), "a = 2\n");
        // A dangling link creates the file it names.
        let dangling = d.path().join("dangling.toml");
        std::os::unix::fs::symlink("new.toml", &dangling).unwrap();
        write_text(&dangling, "b = 1\n", WriteMode::Normal).expect("written");
        assert!(
            fs::symlink_metadata(&dangling)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(
            fs::read_to_string(d.path().join("new.toml")).unwrap(),
            "b = 1\n"
        );
    }

    #[test]
    fn every_hard_link_sees_the_new_text() {
        let d = dir("hardlink");
        let a = d.path().join("a.toml");
        let b = d.path().join("b.toml");
        fs::write(&a, "a = 1\n").unwrap();
        fs::hard_link(&a, &b).unwrap();
        fs::set_permissions(&a, fs::Permissions::from_mode(0o444)).unwrap();
        write_text(&a, "a = 2\n", WriteMode::Force).expect("written");
        assert_eq!(fs::read_to_string(&b).unwrap(), "a = 2\n");
        assert_eq!(mode(&b), 0o444);
    }

    #[test]
    fn a_fifo_a_directory_or_a_device_is_refused_not_replaced() {
        let d = dir("special");
        let fifo = d.path().join("f.toml");
        rustix::fs::mknodat(
            rustix::fs::CWD,
            &fifo,
            rustix::fs::FileType::Fifo,
            rustix::fs::Mode::from_raw_mode(0o644),
            0,
        )
        .expect("mkfifo");
        for (path, kind) in [
            (fifo.as_path(), "a FIFO (named pipe)"),
            (d.path(), "a directory"),
            (Path::new("/dev/null"), "a device"),
        ] {
            match write_text(path, "a = 1\n", WriteMode::Force) {
                Err(WriteError::NotRegular { kind: k, .. }) => assert_eq!(k, kind),
                other => panic!("{}: {other:?}", path.display()),
            }
        }
        assert!(fs::metadata(&fifo).unwrap().file_type().is_fifo());
    }

    #[test]
    fn a_byte_order_mark_and_crlf_line_endings_are_kept() {
        let d = dir("bom");
        let f = d.path().join("s.toml");
        fs::write(&f, "\u{feff}a = 1\r\nb = 2\r\n").unwrap();
        write_text(&f, "a = 1\nb = 3\nc = 4\n", WriteMode::Normal).expect("written");
        assert_eq!(
            fs::read(&f).unwrap(),
            "\u{feff}a = 1\r\nb = 3\r\nc = 4\r\n".as_bytes()
        );
        // A file without them gains neither; a new file is written as given.
        let g = d.path().join("t.toml");
        fs::write(&g, "a = 1\n").unwrap();
        write_text(&g, "a = 2\n", WriteMode::Normal).expect("written");
        assert_eq!(fs::read(&g).unwrap(), b"a = 2\n");
        let h = d.path().join("new.toml");
        write_text(&h, "\u{feff}x = 1\r\n", WriteMode::Normal).expect("created");
        assert_eq!(fs::read(&h).unwrap(), "\u{feff}x = 1\r\n".as_bytes());
    }
}
