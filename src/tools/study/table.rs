//! `study.csv`: one row per point, appended as each point ends. Its header is put in place
//! atomically by the first process; every row is one `write` on a file opened with O_APPEND, so
//! the rows of processes sharing the file never interleave.

use super::StudyError;
use std::collections::HashMap;
use std::fs::OpenOptions;
use std::io::{ErrorKind, Write};
use std::path::Path;

pub const FILE_NAME: &str = "study.csv";

/// Makes sure `path` exists with the header `columns`; refuses a file with another header.
pub fn ensure(path: &Path, columns: &[String]) -> Result<(), StudyError> {
    let header = line(columns);
    let write_error = |source| StudyError::Write {
        path: path.to_owned(),
        source,
    };
    if !path.exists() {
        let private = path.with_extension(format!("new-{}", std::process::id()));
        std::fs::write(&private, &header).map_err(write_error)?;
        let linked = std::fs::hard_link(&private, path);
        std::fs::remove_file(&private).map_err(write_error)?;
        match linked {
            Err(e) if e.kind() != ErrorKind::AlreadyExists => return Err(write_error(e)),
            _ => {}
        }
    }
    let text = read(path)?;
    let found = text.lines().next().unwrap_or_default();
    if found != header.trim_end() {
        return Err(StudyError::Table {
            path: path.to_owned(),
            message: format!(
                "its columns `{found}` are not this study's `{}`: it belongs to another study; give another --out",
                header.trim_end()
            ),
        });
    }
    Ok(())
}

/// Appends one row in a single write.
pub fn append(path: &Path, fields: &[String]) -> Result<(), StudyError> {
    let write_error = |source| StudyError::Write {
        path: path.to_owned(),
        source,
    };
    let mut file = OpenOptions::new()
        .append(true)
        .open(path)
        .map_err(write_error)?;
    file.write_all(line(fields).as_bytes()).map_err(write_error)
}

/// The complete rows of `path`, each a map from column name to field.
pub fn rows(path: &Path) -> Result<Vec<HashMap<String, String>>, StudyError> {
    let text = read(path)?;
    let mut lines = text.split_inclusive('\n').filter(|l| l.ends_with('\n'));
    let columns = split(lines.next().unwrap_or_default().trim_end());
    Ok(lines
        .map(|l| columns.iter().cloned().zip(split(l.trim_end())).collect())
        .collect())
}

fn read(path: &Path) -> Result<String, StudyError> {
    std::fs::read_to_string(path).map_err(|source| StudyError::Read {
        path: path.to_owned(),
        source,
    })
}

/// Fields joined by commas, quoted where they hold a comma, a quote or a line break (line
/// breaks become spaces), ended by a newline.
fn line(fields: &[String]) -> String {
    let quoted: Vec<String> = fields
        .iter()
        .map(|f| {
            let f = f.replace(['\n', '\r'], " ");
            if f.contains([',', '"']) {
                format!("\"{}\"", f.replace('"', "\"\""))
            } else {
                f
            }
        })
        .collect();
    quoted.join(",") + "\n"
}

/// The fields of one CSV line written by `line`.
fn split(line: &str) -> Vec<String> {
    let mut fields = vec![String::new()];
    let (mut quoted, mut chars) = (false, line.chars().peekable());
    while let Some(c) = chars.next() {
        let field = fields.last_mut().expect("fields is never empty");
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                field.push('"');
                chars.next();
            }
            ('"', _) => quoted = !quoted,
            (',', false) => fields.push(String::new()),
            _ => field.push(c),
        }
    }
    fields
}
