//! The CSV files a run appends one row per step to (`stats.csv`, `probes.csv`): written with
//! their header, continued after a checkpoint from a cut-back length, flushed with each frame and
//! fsynced before each checkpoint.

use super::OutputError;
use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

pub struct CsvWriter {
    out: BufWriter<File>,
    path: PathBuf,
}

impl CsvWriter {
    /// A new file at `path` holding `header`.
    pub fn create(path: PathBuf, header: &str) -> Result<Self, OutputError> {
        let file = File::create(&path).map_err(|source| OutputError::Write {
            path: path.clone(),
            source,
        })?;
        let mut w = Self {
            out: BufWriter::new(file),
            path,
        };
        w.line(format_args!("{header}"))?;
        Ok(w)
    }

    /// Continues the file at `path` after its first `length` bytes (see `end_of_row`): the rows
    /// after them are cut off first, durably, so a kill at any instant leaves a prefix.
    pub fn append_at(path: PathBuf, length: u64) -> Result<Self, OutputError> {
        let err = |source| OutputError::Write {
            path: path.clone(),
            source,
        };
        let mut file = OpenOptions::new().write(true).open(&path).map_err(err)?;
        file.set_len(length).map_err(err)?;
        file.sync_data().map_err(err)?;
        file.seek(SeekFrom::End(0)).map_err(err)?;
        Ok(Self {
            out: BufWriter::new(file),
            path,
        })
    }

    /// One line (a row, without its newline).
    pub fn line(&mut self, args: std::fmt::Arguments) -> Result<(), OutputError> {
        writeln!(self.out, "{args}").map_err(|source| OutputError::Write {
            path: self.path.clone(),
            source,
        })
    }

    pub fn flush(&mut self) -> Result<(), OutputError> {
        self.out.flush().map_err(|source| OutputError::Write {
            path: self.path.clone(),
            source,
        })
    }

    /// Flushes and fsyncs, so the rows written so far survive a crash (before a checkpoint
    /// that counts on them).
    pub fn sync(&mut self) -> Result<(), OutputError> {
        self.flush()?;
        self.out
            .get_ref()
            .sync_data()
            .map_err(|source| OutputError::Write {
                path: self.path.clone(),
                source,
            })
    }
}

/// Where a run's CSV file is cut back to on resume: after the header (a checkpoint before the
/// first step), after the row whose first field is `first_field`, or after the first `count`
/// rows (bodies.csv: the rows of the frames a checkpoint counts).
#[derive(Clone, Copy, Debug)]
pub enum CutAt<'a> {
    Header,
    Row {
        first_field: &'a str,
        /// The row as a message names it ("the checkpoint's step 120").
        what: &'a str,
    },
    Rows {
        count: usize,
        what: &'a str,
    },
}

/// Length in bytes of the file at `path` up to and including `at`. Refuses a file whose first
/// line is not `header`, or without that row.
pub fn end_of_row(path: &Path, header: &str, at: CutAt) -> Result<u64, OutputError> {
    let text = std::fs::read(path).map_err(|source| OutputError::Read {
        path: path.to_owned(),
        source,
    })?;
    let mismatch = |what: String| OutputError::Mismatch {
        path: path.to_owned(),
        what,
    };
    // A row cut short by a kill can only be the last line: only complete lines count.
    let mut lines = text
        .split_inclusive(|&b| b == b'\n')
        .filter(|l| l.ends_with(b"\n"));
    let first = lines.next().unwrap_or_default();
    if first != format!("{header}\n").as_bytes() {
        return Err(mismatch(format!(
            "its first line is `{}`, not the header `{header}` this run writes",
            String::from_utf8_lossy(first).trim_end()
        )));
    }
    let mut end = first.len() as u64;
    let (first_field, what) = match at {
        CutAt::Header => return Ok(end),
        CutAt::Rows { count, what } => {
            let rows: Vec<&[u8]> = lines.take(count).collect();
            if rows.len() < count {
                return Err(mismatch(format!(
                    "it holds {} complete rows, fewer than the {count} of {what}",
                    rows.len()
                )));
            }
            return Ok(end + rows.iter().map(|l| l.len() as u64).sum::<u64>());
        }
        CutAt::Row { first_field, what } => (first_field, what),
    };
    let mut last = String::new();
    for line in lines {
        end += line.len() as u64;
        let field = String::from_utf8_lossy(line);
        let field = field.split([',', '\n']).next().unwrap_or_default();
        if field == first_field {
            return Ok(end);
        }
        last = field.to_owned();
    }
    Err(mismatch(format!(
        "it has no row for {what} (its last complete row begins `{last}`)"
    )))
}
