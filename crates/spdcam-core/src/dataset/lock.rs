//! The advisory lock of a dataset directory: one writer at a time.
//!
//! A writer creates `DIR/.spdcam-lock` with `create_new` (atomic: of two runs only one
//! succeeds) holding its pid, host and start time, and removes it when done. A second writer
//! refuses at once, naming the owner. A lock left by a process that no longer runs on this
//! host (killed, crashed) is stale: it is detected and replaced. On Linux a process is
//! identified by its pid and its start time (`/proc/PID/stat`, field 22), so a reused pid is
//! not mistaken for the owner.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The lock file's name inside a dataset directory.
pub const LOCK_FILE: &str = ".spdcam-lock";

/// Who holds a lock.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct LockOwner {
    /// The holding process's id.
    pub pid: u32,
    /// The host name of its machine.
    pub host: String,
    /// The process's start time in clock ticks since boot (Linux), to tell a reused pid.
    pub process_start: Option<u64>,
    /// Seconds since the Unix epoch when the lock was taken.
    pub since_unix_s: u64,
}

impl LockOwner {
    fn current() -> LockOwner {
        LockOwner {
            pid: std::process::id(),
            host: host_name(),
            process_start: process_start(std::process::id()),
            since_unix_s: std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_secs()),
        }
    }

    /// Whether the owner is known to be gone: it ran on this host and no process with its
    /// pid (and start time) runs now. Unknown (another host, no `/proc`) counts as alive.
    fn is_gone(&self) -> bool {
        if self.host != host_name() || !Path::new("/proc/self").exists() {
            return false;
        }
        match process_start(self.pid) {
            None => true,
            Some(start) => self.process_start.is_some_and(|s| s != start),
        }
    }
}

/// This machine's name (`/proc/sys/kernel/hostname`, else `$HOSTNAME`, else "unknown").
fn host_name() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .ok()
        .or_else(|| std::env::var("HOSTNAME").ok())
        .map(|h| h.trim().to_string())
        .filter(|h| !h.is_empty())
        .unwrap_or_else(|| "unknown".to_string())
}

/// The start time of process `pid` in clock ticks since boot, if it runs (Linux only).
fn process_start(pid: u32) -> Option<u64> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    // The command name (field 2) is in parentheses and may hold spaces: count from the last ')'.
    let after = &stat[stat.rfind(')')? + 1..];
    after.split_whitespace().nth(19)?.parse().ok()
}

/// A held lock; released (the file removed) when dropped.
#[derive(Debug)]
pub struct DirLock {
    path: PathBuf,
}

impl DirLock {
    /// Takes the lock of `dir` (which must exist). Refuses when another live process holds
    /// it; replaces a stale lock.
    pub fn acquire(dir: &Path) -> Result<DirLock> {
        let path = dir.join(LOCK_FILE);
        let me = LockOwner::current();
        let mut text =
            serde_json::to_string(&me).map_err(|e| Error::invalid(format!("lock record: {e}")))?;
        text.push('\n');
        for _ in 0..2 {
            match std::fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(&path)
            {
                Ok(mut file) => {
                    file.write_all(text.as_bytes())
                        .map_err(|e| Error::io(&path, e))?;
                    return Ok(DirLock { path });
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    let owner = std::fs::read_to_string(&path)
                        .ok()
                        .and_then(|t| serde_json::from_str::<LockOwner>(&t).ok());
                    match owner {
                        Some(owner) if owner.is_gone() => {
                            // Stale: its process is gone. Another run may race to remove it
                            // too; whoever then creates the file first wins.
                            let _ = std::fs::remove_file(&path);
                        }
                        Some(owner) => return Err(busy(dir, &path, Some(&owner))),
                        None => return Err(busy(dir, &path, None)),
                    }
                }
                Err(e) => return Err(Error::io(&path, e)),
            }
        }
        Err(busy(dir, &path, None))
    }
}

fn busy(dir: &Path, path: &Path, owner: Option<&LockOwner>) -> Error {
    let who = match owner {
        Some(o) => format!("spdcam process {} on host {}", o.pid, o.host),
        None => "another spdcam process (its lock record is unreadable)".to_string(),
    };
    Error::invalid(format!(
        "dataset directory {} is in use by {who}: two runs must not write one directory; \
         wait for it to finish, or, if that process is gone, remove {}",
        dir.display(),
        path.display()
    ))
}

impl Drop for DirLock {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("spdcam-lock-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn a_second_writer_refuses_and_the_lock_goes_with_the_first() {
        let dir = scratch("busy");
        let first = DirLock::acquire(&dir).unwrap();
        let e = DirLock::acquire(&dir).unwrap_err().to_string();
        assert!(
            e.contains(&format!("process {}", std::process::id())),
            "{e}"
        );
        assert!(e.contains(LOCK_FILE), "{e}");
        drop(first);
        assert!(!dir.join(LOCK_FILE).exists());
        drop(DirLock::acquire(&dir).unwrap());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn a_lock_of_a_dead_process_is_stale_and_replaced() {
        let dir = scratch("stale");
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let pid = child.id();
        child.wait().unwrap();
        let dead = LockOwner {
            pid,
            host: host_name(),
            process_start: Some(1),
            since_unix_s: 0,
        };
        assert!(dead.is_gone());
        std::fs::write(dir.join(LOCK_FILE), serde_json::to_string(&dead).unwrap()).unwrap();
        let lock = DirLock::acquire(&dir).unwrap();
        let now: LockOwner =
            serde_json::from_str(&std::fs::read_to_string(dir.join(LOCK_FILE)).unwrap()).unwrap();
        assert_eq!(now.pid, std::process::id());
        drop(lock);
        // A live owner whose recorded start time differs is a reused pid: stale as well.
        let reused = LockOwner {
            process_start: process_start(std::process::id()).map(|s| s + 1),
            ..LockOwner::current()
        };
        assert!(reused.is_gone());
        assert!(!LockOwner::current().is_gone());
        let elsewhere = LockOwner {
            host: "another-host".into(),
            pid,
            ..dead
        };
        assert!(!elsewhere.is_gone());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
