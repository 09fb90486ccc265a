//! Child processes of `isph` that measure themselves. `isph bench` and `isph study` run each
//! point in a process of its own, so that the peak resident memory (VmHWM) it reports is that
//! point's alone; the child prints what it measured as TOML on stdout, and the parent reads it
//! back with [`run`].

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;
use std::process::{Command, ExitStatus};

#[derive(Debug, thiserror::Error)]
pub enum ChildError {
    #[error("cannot start {}: {source}", exe.display())]
    Spawn {
        exe: PathBuf,
        source: std::io::Error,
    },
    #[error("it failed ({status}): {message}")]
    Failed { status: String, message: String },
    #[error("its report came back unreadable: {message}")]
    Report { message: String },
    #[error("cannot read the peak resident memory (VmHWM) from /proc/self/status: {message}")]
    Memory { message: String },
}

/// What a child `isph run --report` prints of itself when its run has ended.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunReport {
    /// VmHWM at the end of the run [bytes].
    pub peak_rss_bytes: u64,
}

impl RunReport {
    pub fn of_this_process() -> Result<Self, ChildError> {
        Ok(Self {
            peak_rss_bytes: peak_resident_bytes()?,
        })
    }

    pub fn to_toml(&self) -> String {
        toml::to_string(self).expect("a RunReport is plain numbers")
    }
}

/// The peak resident set size of this process so far (VmHWM).
pub fn peak_resident_bytes() -> Result<u64, ChildError> {
    crate::math::memory::proc_bytes("/proc/self/status", "VmHWM")
        .map_err(|message| ChildError::Memory { message })
}

/// Runs `command` to its end and reads the TOML report it prints on stdout. A child that
/// fails gives its exit status and the message it printed on stderr.
pub fn run<T: DeserializeOwned>(command: &mut Command) -> Result<T, ChildError> {
    let output = command.output().map_err(|source| ChildError::Spawn {
        exe: PathBuf::from(command.get_program()),
        source,
    })?;
    if !output.status.success() {
        let stderr = String::from_utf8_lossy(&output.stderr);
        let message = stderr.trim().trim_start_matches("error: ").to_owned();
        return Err(ChildError::Failed {
            status: describe_exit(output.status),
            message: if message.is_empty() {
                "no message".into()
            } else {
                message
            },
        });
    }
    let text = String::from_utf8_lossy(&output.stdout);
    toml::from_str(&text).map_err(|e| ChildError::Report {
        message: e.to_string(),
    })
}

fn describe_exit(status: ExitStatus) -> String {
    use std::os::unix::process::ExitStatusExt;
    match (status.code(), status.signal()) {
        (Some(code), _) => format!("exit code {code}"),
        // SIGKILL is what the kernel's out-of-memory killer sends.
        (None, Some(9)) => "killed by signal 9, perhaps out of memory".into(),
        (None, Some(s)) => format!("killed by signal {s}"),
        (None, None) => "ended abnormally".into(),
    }
}
