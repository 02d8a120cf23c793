//! File helpers: atomic writes (every file the engine writes is written whole or not at all),
//! RON reading with located errors, and where the shared motion data is.

use std::io::Write;
use std::path::{Path, PathBuf};

/// Writes `bytes` to `path` atomically: into a temporary file beside it, then renamed over it,
/// so a reader never sees a half-written file and a failed run leaves no partial output.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path.file_name().ok_or_else(|| {
        std::io::Error::new(std::io::ErrorKind::InvalidInput, "path has no file name")
    })?;
    // Unique per process and per call, so concurrent writers never share a temporary file.
    static COUNTER: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(name);
    tmp_name.push(format!(".tmp{}-{n}", std::process::id()));
    let tmp = dir.join(tmp_name);
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    if result.is_ok() {
        remove_stale_temporaries(dir, name);
    }
    result
}

/// Removes the temporary files `.NAME.tmpPID-N` of `dir` that a process killed between its write
/// and its rename left behind (a checkpoint saved every generation would gather one per kill):
/// those of a process that no longer runs, as `/proc` tells; nothing where there is no `/proc`.
fn remove_stale_temporaries(dir: &Path, name: &std::ffi::OsStr) {
    let proc_fs = Path::new("/proc");
    if !proc_fs.join("self").exists() {
        return;
    }
    let prefix = format!(".{}.tmp", name.to_string_lossy());
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let file = entry.file_name();
        let Some(rest) = file.to_str().and_then(|f| f.strip_prefix(&prefix)) else {
            continue;
        };
        let Some((pid, n)) = rest.split_once('-') else {
            continue;
        };
        let (Ok(pid), Ok(_)) = (pid.parse::<u32>(), n.parse::<u64>()) else {
            continue;
        };
        if pid != std::process::id() && !proc_fs.join(pid.to_string()).exists() {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// The motion data folder: `$MARIONETTE_DATA`, else `../shared/data`; a relative path is taken
/// from the current working directory (not the build directory), so `cargo run` and
/// `cargo test` in the crate's folder find the project's `../shared/data`.
pub fn data_dir() -> PathBuf {
    let dir = match std::env::var_os("MARIONETTE_DATA") {
        Some(d) if !d.is_empty() => PathBuf::from(d),
        _ => PathBuf::from("../shared/data"),
    };
    if dir.is_absolute() {
        return dir;
    }
    let joined = match std::env::current_dir() {
        Ok(cwd) => cwd.join(&dir),
        Err(_) => dir,
    };
    joined.canonicalize().unwrap_or(joined)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dead_writers_temporary_is_removed_by_the_next_write() {
        let dir = std::env::temp_dir().join(format!("marionette-io-stale-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // PID 4194305 is above Linux's largest (2^22): never a running process.
        let dead = dir.join(".checkpoint.json.tmp4194305-3");
        let other = dir.join(".other.json.tmp4194305-3");
        std::fs::write(&dead, b"half").unwrap();
        std::fs::write(&other, b"half").unwrap();
        write_atomic(&dir.join("checkpoint.json"), b"whole").unwrap();
        if Path::new("/proc/self").exists() {
            assert!(!dead.exists(), "the dead writer's temporary is left");
        }
        assert!(other.exists(), "another file's temporary was touched");
        assert_eq!(
            std::fs::read(dir.join("checkpoint.json")).unwrap(),
            b"whole"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn writes_whole_file_and_leaves_no_temporary() {
        let dir = std::env::temp_dir().join(format!("marionette-io-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("a.txt");
        write_atomic(&p, b"hello").unwrap();
        write_atomic(&p, b"world!").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"world!");
        let names: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names.len(), 1, "temporary files left behind: {names:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn failed_write_leaves_nothing() {
        let p = Path::new("/nonexistent-dir-marionette/x.txt");
        assert!(write_atomic(p, b"x").is_err());
    }
}

/// Why a data file (RON) could not be read: the file itself, its syntax, or its version.
#[derive(Debug, thiserror::Error)]
pub enum FileError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The operating system's reason.
        source: std::io::Error,
    },
    /// RON syntax or schema error, with line and column.
    #[error(transparent)]
    Ron(#[from] RonError),
    /// A format version newer than this build reads, or 0.
    #[error(
        "{path}: format_version {found} is not one this build reads (1 to {supported}; \
         {found} is {})",
        if *found == 0 { "not a version: versions start at 1" } else { "newer" }
    )]
    Version {
        /// The file.
        path: String,
        /// The version in the file.
        found: u32,
        /// The newest version this build reads.
        supported: u32,
    },
}

/// Reads a whole text file, naming it in the error.
pub fn read_text(path: &Path) -> Result<String, FileError> {
    std::fs::read_to_string(path).map_err(|source| FileError::Io {
        path: path.display().to_string(),
        source,
    })
}

/// Refuses a `format_version` newer than `supported`, or 0 (versions start at 1).
pub fn check_version(origin: &str, found: u32, supported: u32) -> Result<(), FileError> {
    if found == 0 {
        return Err(FileError::Version {
            path: origin.to_string(),
            found,
            supported,
        });
    }
    if found > supported {
        return Err(FileError::Version {
            path: origin.to_string(),
            found,
            supported,
        });
    }
    Ok(())
}

/// A RON syntax or schema error, located: `path:line:column: message`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{path}:{line}:{column}: {message}")]
pub struct RonError {
    /// File (or other origin) of the text.
    pub path: String,
    /// 1-based line.
    pub line: usize,
    /// 1-based column.
    pub column: usize,
    /// What was wrong or expected (ron's message, naming the field).
    pub message: String,
}

/// Parses RON text the way every marionette file is read: `Option` fields may be written
/// without `Some(…)` (ron's `implicit_some`) and a variant holding a struct as `Variant(a: 1)`
/// (`unwrap_variant_newtypes`); errors carry `origin`, line and column.
pub fn parse_ron<T: serde::de::DeserializeOwned>(text: &str, origin: &str) -> Result<T, RonError> {
    ron::Options::default()
        .with_default_extension(
            ron::extensions::Extensions::IMPLICIT_SOME
                | ron::extensions::Extensions::UNWRAP_VARIANT_NEWTYPES,
        )
        .from_str(text)
        .map_err(|e| RonError {
            path: origin.to_string(),
            line: e.span.start.line,
            column: e.span.start.col,
            message: e.code.to_string(),
        })
}

/// Deserializes a map, refusing a key given twice (serde's maps keep the last value silently:
/// a weight written twice would keep only its second value). Use with
/// `#[serde(deserialize_with = "crate::io::unique_keys")]`.
pub fn unique_keys<'de, D, K, V>(d: D) -> Result<std::collections::BTreeMap<K, V>, D::Error>
where
    D: serde::Deserializer<'de>,
    K: serde::Deserialize<'de> + Ord + std::fmt::Debug,
    V: serde::Deserialize<'de>,
{
    struct Unique<K, V>(std::marker::PhantomData<(K, V)>);
    impl<'de, K, V> serde::de::Visitor<'de> for Unique<K, V>
    where
        K: serde::Deserialize<'de> + Ord + std::fmt::Debug,
        V: serde::Deserialize<'de>,
    {
        type Value = std::collections::BTreeMap<K, V>;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("a map with each key once")
        }
        fn visit_map<A: serde::de::MapAccess<'de>>(
            self,
            mut map: A,
        ) -> Result<Self::Value, A::Error> {
            let mut out = std::collections::BTreeMap::new();
            while let Some((k, v)) = map.next_entry::<K, V>()? {
                if out.contains_key(&k) {
                    return Err(serde::de::Error::custom(format!(
                        "the key {k:?} is given twice"
                    )));
                }
                out.insert(k, v);
            }
            Ok(out)
        }
    }
    d.deserialize_map(Unique(std::marker::PhantomData))
}

/// [`unique_keys`] for an optional map.
pub fn unique_keys_opt<'de, D, K, V>(
    d: D,
) -> Result<Option<std::collections::BTreeMap<K, V>>, D::Error>
where
    D: serde::Deserializer<'de>,
    K: serde::Deserialize<'de> + Ord + std::fmt::Debug,
    V: serde::Deserialize<'de>,
{
    struct Wrap<K, V>(std::collections::BTreeMap<K, V>);
    impl<'de, K, V> serde::Deserialize<'de> for Wrap<K, V>
    where
        K: serde::Deserialize<'de> + Ord + std::fmt::Debug,
        V: serde::Deserialize<'de>,
    {
        fn deserialize<E: serde::Deserializer<'de>>(d: E) -> Result<Self, E::Error> {
            unique_keys(d).map(Wrap)
        }
    }
    Ok(<Option<Wrap<K, V>> as serde::Deserialize>::deserialize(d)?.map(|w| w.0))
}

#[cfg(test)]
mod unique_keys_tests {
    use std::collections::BTreeMap;

    #[derive(serde::Deserialize, Debug)]
    struct W {
        #[serde(rename = "w", deserialize_with = "super::unique_keys")]
        _w: BTreeMap<String, f64>,
        #[serde(default, deserialize_with = "super::unique_keys_opt")]
        o: Option<BTreeMap<String, f64>>,
    }

    #[test]
    fn a_key_given_twice_is_refused_with_its_place() {
        let e = super::parse_ron::<W>("(w: {\"knee\": 1.0, \"hip\": 2.0, \"knee\": 3.0})", "f.ron")
            .unwrap_err();
        assert!(e.message.contains("the key \"knee\" is given twice"), "{e}");
        assert_eq!(e.line, 1, "{e}");
        let e = super::parse_ron::<W>("(w: {}, o: {\"a\": 1.0, \"a\": 1.0})", "f.ron").unwrap_err();
        assert!(e.message.contains("\"a\" is given twice"), "{e}");
        let ok = super::parse_ron::<W>("(w: {\"a\": 1.0}, o: {\"b\": 2.0})", "f.ron").unwrap();
        assert_eq!(ok.o.unwrap()["b"], 2.0);
        assert!(
            super::parse_ron::<W>("(w: {})", "f.ron")
                .unwrap()
                .o
                .is_none()
        );
    }
}
