//! Finding what a report shows under a folder: failed goldens (`NAME.actual.png` beside
//! `NAME.png`), `compare` folders (`gpu.png` and `reference.png`), `sweep` folders
//! (`sweep.json`) and `stability` folders (`stability.json`).

use super::ReportError;
use serde_json::Value;
use std::path::{Path, PathBuf};

/// Folders the walk does not enter: build trees and package caches, where a report has nothing
/// to find and a walk would take minutes.
const SKIPPED: [&str; 3] = ["target", "node_modules", "__pycache__"];
/// How deep the walk goes below the folder.
const MAX_DEPTH: usize = 12;
/// How many entries the walk reads at most (a folder of millions of files is not a report).
const MAX_ENTRIES: usize = 200_000;

/// A golden that failed: what `umbra::golden` left beside it.
#[derive(Clone, Debug)]
pub struct GoldenFailure {
    /// The golden's name (`demo` for `demo.png`).
    pub name: String,
    /// The golden.
    pub golden: PathBuf,
    /// `NAME.actual.png`.
    pub actual: PathBuf,
    /// `NAME.diff.png`, the FLIP heat map.
    pub diff: Option<PathBuf>,
    /// `NAME.shadow.png`, `NAME.actual.shadow.png` and `NAME.shadow-diff.png`, where the golden
    /// keeps a shadow view.
    pub shadow: Option<[PathBuf; 3]>,
    /// `NAME.failure.json` (the one-line reason and the figures), where written.
    pub failure: Option<Value>,
}

/// A `compare` output folder.
#[derive(Clone, Debug)]
pub struct CompareRun {
    /// The folder.
    pub dir: PathBuf,
    /// `compare.json`, where written.
    pub json: Option<Value>,
}

/// A `sweep` output folder.
#[derive(Clone, Debug)]
pub struct SweepRun {
    /// The folder.
    pub dir: PathBuf,
    /// `sweep.json`'s rows.
    pub rows: Vec<Value>,
}

/// A `stability` output folder.
#[derive(Clone, Debug)]
pub struct StabilityRun {
    /// The folder.
    pub dir: PathBuf,
    /// `stability.json`.
    pub json: Value,
    /// The charts (`*.png` in the folder), by name.
    pub charts: Vec<PathBuf>,
}

/// Everything found under a folder, each kind in path order.
#[derive(Clone, Debug, Default)]
pub struct Found {
    /// Failed goldens.
    pub goldens: Vec<GoldenFailure>,
    /// `compare` folders.
    pub compares: Vec<CompareRun>,
    /// `sweep` folders.
    pub sweeps: Vec<SweepRun>,
    /// `stability` folders.
    pub stabilities: Vec<StabilityRun>,
}

/// Walks `root` (symbolic links are not followed, hidden folders and build trees are skipped)
/// and collects what a report shows.
pub fn scan(root: &Path) -> Result<Found, ReportError> {
    if !root.is_dir() {
        return Err(ReportError::NotAFolder(root.to_path_buf()));
    }
    let mut found = Found::default();
    let mut stack = vec![(root.to_path_buf(), 0usize)];
    let mut entries = 0usize;
    while let Some((dir, depth)) = stack.pop() {
        let mut files = Vec::new();
        let mut dirs = Vec::new();
        let read = std::fs::read_dir(&dir).map_err(|e| ReportError::io(&dir, e))?;
        for e in read {
            let e = e.map_err(|e| ReportError::io(&dir, e))?;
            entries += 1;
            if entries > MAX_ENTRIES {
                return Err(ReportError::TooLarge(root.to_path_buf(), MAX_ENTRIES));
            }
            let name = e.file_name().to_string_lossy().into_owned();
            let kind = e
                .file_type()
                .map_err(|err| ReportError::io(&e.path(), err))?;
            if kind.is_dir() && !name.starts_with('.') && !SKIPPED.contains(&name.as_str()) {
                dirs.push(e.path());
            } else if kind.is_file() {
                files.push(name);
            }
        }
        files.sort();
        collect(&dir, &files, &mut found)?;
        if depth < MAX_DEPTH {
            dirs.sort();
            stack.extend(dirs.into_iter().rev().map(|d| (d, depth + 1)));
        }
    }
    Ok(found)
}

/// What the files of one folder hold.
fn collect(dir: &Path, files: &[String], found: &mut Found) -> Result<(), ReportError> {
    let has = |n: &str| files.iter().any(|f| f == n);
    let opt = |n: String| has(&n).then(|| dir.join(n));
    for f in files {
        let Some(name) = f.strip_suffix(".actual.png") else {
            continue;
        };
        if !has(&format!("{name}.png")) {
            continue;
        }
        let shadow = match (
            opt(format!("{name}.shadow.png")),
            opt(format!("{name}.actual.shadow.png")),
            opt(format!("{name}.shadow-diff.png")),
        ) {
            (Some(a), Some(b), Some(c)) => Some([a, b, c]),
            _ => None,
        };
        let failure = match opt(format!("{name}.failure.json")) {
            Some(p) => Some(read_json(&p)?),
            None => None,
        };
        found.goldens.push(GoldenFailure {
            name: name.to_string(),
            golden: dir.join(format!("{name}.png")),
            actual: dir.join(f),
            diff: opt(format!("{name}.diff.png")),
            shadow,
            failure,
        });
    }
    if has("gpu.png") && has("reference.png") {
        let json = match opt("compare.json".into()) {
            Some(p) => Some(read_json(&p)?),
            None => None,
        };
        found.compares.push(CompareRun {
            dir: dir.to_path_buf(),
            json,
        });
    }
    if has("sweep.json") {
        let p = dir.join("sweep.json");
        let rows = match read_json(&p)? {
            Value::Object(mut doc) => match doc.remove("rows") {
                Some(Value::Array(rows)) => rows,
                _ => return Err(ReportError::Format(p, "no \"rows\" array".into())),
            },
            _ => return Err(ReportError::Format(p, "not a sweep document".into())),
        };
        found.sweeps.push(SweepRun {
            dir: dir.to_path_buf(),
            rows,
        });
    }
    if has("stability.json") {
        let charts = files
            .iter()
            .filter(|f| f.ends_with(".png"))
            .map(|f| dir.join(f))
            .collect();
        found.stabilities.push(StabilityRun {
            dir: dir.to_path_buf(),
            json: read_json(&dir.join("stability.json"))?,
            charts,
        });
    }
    Ok(())
}

/// A JSON file, parsed.
fn read_json(p: &Path) -> Result<Value, ReportError> {
    let bytes = std::fs::read(p).map_err(|e| ReportError::io(p, e))?;
    serde_json::from_slice(&bytes).map_err(|e| ReportError::Format(p.to_path_buf(), e.to_string()))
}
