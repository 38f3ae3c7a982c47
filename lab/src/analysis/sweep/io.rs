//! Sweep files: rows read from and appended to CSV (flushed per row, so a sweep resumes where
//! it stopped) and written as JSON.

use super::Row;
use std::path::Path;

/// Errors reading or writing sweep files.
#[derive(Debug, thiserror::Error)]
pub enum SweepIoError {
    /// A CSV problem (with the file).
    #[error("{path}: {source}")]
    Csv {
        /// The file.
        path: String,
        /// What went wrong.
        source: csv::Error,
    },
    /// A file-system problem.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// What went wrong.
        source: std::io::Error,
    },
}

/// Reads the rows of a sweep CSV (an absent file is no rows).
pub fn read_csv(path: &Path) -> Result<Vec<Row>, SweepIoError> {
    if !path.exists() {
        return Ok(Vec::new());
    }
    let p = path.display().to_string();
    let mut r = csv::Reader::from_path(path).map_err(|source| SweepIoError::Csv {
        path: p.clone(),
        source,
    })?;
    r.deserialize()
        .collect::<Result<Vec<Row>, _>>()
        .map_err(|source| SweepIoError::Csv { path: p, source })
}

/// Appends rows to a CSV, writing the header first when the file is new or empty. Each row is
/// flushed, so an interrupted sweep loses nothing it measured.
pub struct CsvAppender {
    writer: csv::Writer<std::fs::File>,
    path: String,
}

impl CsvAppender {
    /// Opens (or creates) `path` for appending.
    pub fn open(path: &Path) -> Result<Self, SweepIoError> {
        let p = path.display().to_string();
        let io = |source| SweepIoError::Io {
            path: p.clone(),
            source,
        };
        let fresh = std::fs::metadata(path)
            .map(|m| m.len() == 0)
            .unwrap_or(true);
        let file = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
            .map_err(io)?;
        let writer = csv::WriterBuilder::new()
            .has_headers(fresh)
            .from_writer(file);
        Ok(Self { writer, path: p })
    }

    /// Appends one row and flushes it.
    pub fn push(&mut self, row: &Row) -> Result<(), SweepIoError> {
        self.writer
            .serialize(row)
            .map_err(|source| SweepIoError::Csv {
                path: self.path.clone(),
                source,
            })?;
        self.writer.flush().map_err(|source| SweepIoError::Io {
            path: self.path.clone(),
            source,
        })
    }
}

/// Writes `rows` as a JSON document `{"schema": "umbra-sweep/1", "rows": [...]}`.
pub fn write_json(path: &Path, rows: &[Row]) -> Result<(), SweepIoError> {
    let doc = serde_json::json!({ "schema": "umbra-sweep/1", "rows": rows });
    std::fs::write(path, serde_json::to_string_pretty(&doc).unwrap_or_default()).map_err(|source| {
        SweepIoError::Io {
            path: path.display().to_string(),
            source,
        }
    })
}
