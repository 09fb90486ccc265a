//! Claims on a study's points, so that two `isph study` processes on the same output directory
//! never run the same point. A claim is the file `points/<id>/claim` holding the claimant's pid
//! and start time; it is created atomically with its content (written under a private name,
//! then hard-linked into place, which fails if the claim exists), and removed when the point's
//! row is written. A claim whose process is gone (no such pid, or a pid reused by a process that
//! started later) is stale and taken over.

use std::io::ErrorKind;
use std::path::{Path, PathBuf};

pub const FILE_NAME: &str = "claim";

/// A claim this process holds; dropping it releases the point.
#[derive(Debug)]
pub struct Claim {
    path: PathBuf,
}

impl Drop for Claim {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

/// Claims the point whose directory is `dir`: None when a live process holds it.
pub fn claim(dir: &Path) -> std::io::Result<Option<Claim>> {
    let path = dir.join(FILE_NAME);
    let me = identity(std::process::id()).unwrap_or_default();
    // Two tries: the second after taking over a stale claim.
    for _ in 0..2 {
        if create_with(&path, &me)? {
            return Ok(Some(Claim { path }));
        }
        let holder = match std::fs::read_to_string(&path) {
            Ok(text) => text,
            Err(e) if e.kind() == ErrorKind::NotFound => continue,
            Err(e) => return Err(e),
        };
        if is_alive(&holder) || !take_over(&path, &holder)? {
            return Ok(None);
        }
    }
    Ok(None)
}

/// Creates `path` holding `content`, atomically; false when it exists.
fn create_with(path: &Path, content: &str) -> std::io::Result<bool> {
    let private = path.with_extension(format!("new-{}", std::process::id()));
    std::fs::write(&private, content)?;
    let linked = std::fs::hard_link(&private, path);
    std::fs::remove_file(&private)?;
    match linked {
        Ok(()) => Ok(true),
        Err(e) if e.kind() == ErrorKind::AlreadyExists => Ok(false),
        Err(e) => Err(e),
    }
}

/// Removes the stale claim `path` whose content was `stale`; false when another process got
/// there first (the claim then in place is put back).
fn take_over(path: &Path, stale: &str) -> std::io::Result<bool> {
    let aside = path.with_extension(format!("stale-{}", std::process::id()));
    match std::fs::rename(path, &aside) {
        Ok(()) => {}
        Err(e) if e.kind() == ErrorKind::NotFound => return Ok(true),
        Err(e) => return Err(e),
    }
    let moved = std::fs::read_to_string(&aside)?;
    if moved != stale {
        // A fresh claim of another process: put it back unless a third one is in place.
        let _ = std::fs::hard_link(&aside, path);
    }
    std::fs::remove_file(&aside)?;
    Ok(moved == stale)
}

/// "pid start-time" of process `pid`, None when there is no such process.
fn identity(pid: u32) -> Option<String> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    // Field 22 (start time in clock ticks since boot) counts from after the command name,
    // which ends at the last ')'.
    let after_name = &stat[stat.rfind(')')? + 1..];
    let start = after_name.split_whitespace().nth(19)?;
    Some(format!("{pid} {start}"))
}

/// Whether the process that wrote the claim `holder` still runs.
fn is_alive(holder: &str) -> bool {
    let pid = holder
        .split_whitespace()
        .next()
        .and_then(|p| p.parse().ok());
    pid.and_then(identity)
        .is_some_and(|now| now.trim() == holder.trim())
}
