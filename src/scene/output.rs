//! A scene's output folder written all at once: outputs go into a temporary folder beside the
//! target, which replaces the target only when everything is written.

use std::path::{Path, PathBuf};

use super::SceneError;

/// Marks a temporary folder of a run in progress (`.<folder>.partial-<pid>`).
const PARTIAL: &str = ".partial-";
/// Marks the previous outputs while they are being replaced (`.<folder>.old-<pid>`).
const OLD: &str = ".old-";

fn io_error(path: &Path, source: std::io::Error) -> SceneError {
    SceneError::Io {
        path: path.display().to_string(),
        source,
    }
}

/// A run's temporary output folder; dropped without [`Staging::commit`], it is removed and the
/// target is left as it was.
pub struct Staging {
    target: PathBuf,
    tmp: PathBuf,
    committed: bool,
}

/// Whether the process `pid` still runs (Linux: `/proc/<pid>`; elsewhere taken as gone).
fn alive(pid: u32) -> bool {
    pid == std::process::id() || Path::new("/proc").join(pid.to_string()).exists()
}

impl Staging {
    /// Checks `target` may be replaced (absent, empty, or holding a `report.json`), removes the
    /// temporary folders of interrupted runs beside it, and creates this run's.
    pub fn begin(target: &Path) -> Result<Staging, SceneError> {
        let name = target
            .file_name()
            .ok_or_else(|| SceneError::OutputName(target.to_path_buf()))?
            .to_string_lossy()
            .to_string();
        let parent = match target.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        if target.exists() {
            if !target.is_dir() {
                return Err(SceneError::OutputIsFile(target.to_path_buf()));
            }
            let mut entries = std::fs::read_dir(target).map_err(|e| io_error(target, e))?;
            if entries.next().is_some() && !target.join("report.json").is_file() {
                return Err(SceneError::NotSceneOutput(target.to_path_buf()));
            }
        }
        std::fs::create_dir_all(&parent).map_err(|e| io_error(&parent, e))?;
        // Folders of runs that were interrupted: their process is gone. A run killed between
        // the two renames of `commit` left the previous outputs as `.old-`: they are put back
        // first, so an interruption at any moment leaves the previous outputs in place.
        if let Ok(entries) = std::fs::read_dir(&parent) {
            let prefix = format!(".{name}");
            for e in entries.flatten() {
                let f = e.file_name().to_string_lossy().to_string();
                let Some(rest) = f.strip_prefix(&prefix) else {
                    continue;
                };
                let pid = rest
                    .strip_prefix(PARTIAL)
                    .or_else(|| rest.strip_prefix(OLD))
                    .and_then(|p| p.parse::<u32>().ok());
                if let Some(pid) = pid
                    && !alive(pid)
                {
                    if rest.starts_with(OLD) && !target.exists() {
                        std::fs::rename(e.path(), target).map_err(|err| io_error(target, err))?;
                    } else {
                        let _ = std::fs::remove_dir_all(e.path());
                    }
                }
            }
        }
        let tmp = parent.join(format!(".{name}{PARTIAL}{}", std::process::id()));
        if tmp.exists() {
            std::fs::remove_dir_all(&tmp).map_err(|e| io_error(&tmp, e))?;
        }
        std::fs::create_dir(&tmp).map_err(|e| io_error(&tmp, e))?;
        Ok(Staging {
            target: target.to_path_buf(),
            tmp,
            committed: false,
        })
    }

    /// The temporary folder to write into.
    pub fn path(&self) -> &Path {
        &self.tmp
    }

    /// Puts the outputs in place of the target's previous ones (two renames on one file
    /// system; the previous folder is removed after).
    pub fn commit(mut self) -> Result<(), SceneError> {
        let old = self.tmp.with_file_name(
            self.tmp
                .file_name()
                .unwrap_or_default()
                .to_string_lossy()
                .replace(PARTIAL, OLD),
        );
        let had_old = self.target.exists();
        if had_old {
            std::fs::rename(&self.target, &old).map_err(|e| io_error(&self.target, e))?;
        }
        if let Err(e) = std::fs::rename(&self.tmp, &self.target) {
            if had_old {
                let _ = std::fs::rename(&old, &self.target);
            }
            return Err(io_error(&self.target, e));
        }
        self.committed = true;
        if had_old {
            let _ = std::fs::remove_dir_all(&old);
        }
        Ok(())
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_dir_all(&self.tmp);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("marionette-stage-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn commit_replaces_whole_and_drop_keeps_the_old() {
        let d = scratch("commit");
        let target = d.join("out");
        std::fs::create_dir(&target).unwrap();
        std::fs::write(target.join("report.json"), "old").unwrap();
        std::fs::write(target.join("stale.png"), "old").unwrap();
        // A failed run: the old outputs stay as they were.
        {
            let s = Staging::begin(&target).unwrap();
            std::fs::write(s.path().join("motion.bvh"), "new").unwrap();
        }
        assert_eq!(
            std::fs::read_to_string(target.join("report.json")).unwrap(),
            "old"
        );
        assert!(!target.join("motion.bvh").exists());
        // A run that succeeds: only the new files, nothing of the old run beside them.
        let s = Staging::begin(&target).unwrap();
        std::fs::write(s.path().join("report.json"), "new").unwrap();
        s.commit().unwrap();
        assert_eq!(
            std::fs::read_to_string(target.join("report.json")).unwrap(),
            "new"
        );
        assert!(!target.join("stale.png").exists());
        let names: Vec<_> = std::fs::read_dir(&d)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, ["out"], "temporary folders left: {names:?}");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn removes_folders_of_interrupted_runs_and_refuses_foreign_folders() {
        let d = scratch("stale");
        // A pid that cannot be running (above Linux's pid_max).
        let stale = d.join(".out.partial-4294967295");
        std::fs::create_dir(&stale).unwrap();
        std::fs::write(stale.join("motion.bvh"), "half").unwrap();
        let s = Staging::begin(&d.join("out")).unwrap();
        assert!(!stale.exists());
        drop(s);
        let foreign = d.join("mine");
        std::fs::create_dir(&foreign).unwrap();
        std::fs::write(foreign.join("notes.txt"), "keep").unwrap();
        let e = Staging::begin(&foreign).err().unwrap().to_string();
        assert!(e.contains("not a scene's output"), "{e}");
        assert!(foreign.join("notes.txt").exists());
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_run_killed_between_the_renames_leaves_the_previous_outputs() {
        let d = scratch("window");
        // Killed after `target → .old-` and before `.partial- → target`.
        let old = d.join(".out.old-4294967295");
        std::fs::create_dir(&old).unwrap();
        std::fs::write(old.join("report.json"), "previous").unwrap();
        let half = d.join(".out.partial-4294967295");
        std::fs::create_dir(&half).unwrap();
        std::fs::write(half.join("report.json"), "unfinished").unwrap();
        let target = d.join("out");
        let s = Staging::begin(&target).unwrap();
        assert_eq!(
            std::fs::read_to_string(target.join("report.json")).unwrap(),
            "previous"
        );
        assert!(!old.exists() && !half.exists());
        drop(s);
        assert_eq!(
            std::fs::read_to_string(target.join("report.json")).unwrap(),
            "previous"
        );
        std::fs::remove_dir_all(&d).unwrap();
    }
}
