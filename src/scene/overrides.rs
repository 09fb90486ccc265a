//! A point's settings written into the scene's text with `toml_edit`: comments, order and
//! formatting of the rest of the file stay as they were.

use toml_edit::{DocumentMut, Item, Table};

/// Why a setting cannot be written into the scene text.
#[derive(Debug, thiserror::Error)]
#[error("{message}")]
pub struct OverrideError {
    pub message: String,
}

/// `text` with each (dotted key, value) set: missing tables and keys are created; a key whose
/// path runs through a value or an array of tables is an error.
pub fn apply(text: &str, settings: &[(String, toml::Value)]) -> Result<String, OverrideError> {
    let mut doc: DocumentMut = text.parse().map_err(|e| OverrideError {
        message: format!("the scene is not TOML: {e}"),
    })?;
    for (key, value) in settings {
        set(&mut doc, key, value)?;
    }
    Ok(doc.to_string())
}

fn set(doc: &mut DocumentMut, key: &str, value: &toml::Value) -> Result<(), OverrideError> {
    let error = |message: String| OverrideError { message };
    let new: toml_edit::Value = value
        .to_string()
        .parse()
        .map_err(|e| error(format!("{value} is not a TOML value: {e}")))?;
    let parts: Vec<&str> = key.split('.').collect();
    let (last, path) = parts.split_last().expect("split gives one part at least");
    let mut table = doc.as_table_mut() as &mut dyn toml_edit::TableLike;
    for (k, part) in path.iter().enumerate() {
        let item = table.entry(part).or_insert_with(|| {
            let mut t = Table::new();
            t.set_implicit(true);
            Item::Table(t)
        });
        table = item.as_table_like_mut().ok_or_else(|| {
            error(format!(
                "`{}` is not a table, so `{key}` cannot be set",
                path[..=k].join(".")
            ))
        })?;
    }
    match table.get_mut(last) {
        Some(Item::Value(old)) => {
            let decor = old.decor().clone();
            *old = new;
            *old.decor_mut() = decor;
        }
        Some(_) => {
            return Err(error(format!(
                "`{key}` is a table or an array of tables, not a value"
            )))
        }
        None => {
            table.insert(last, Item::Value(new));
        }
    }
    Ok(())
}
