//! `umbra report DIR`: one self-contained HTML page (images inlined as data URIs, the controls
//! in an inline script: no server, no network) of what lies under a folder:
//!
//! - **failed goldens** (what `umbra::golden` leaves beside a golden: `NAME.actual.png`,
//!   `NAME.diff.png`, the shadow views, `NAME.failure.json`): golden, actual and FLIP diff side
//!   by side, a slider and a blink between golden and actual, zoom, the figures;
//! - **`compare` folders**: reference, GPU frame and diff the same way, `compare.json` as a table;
//! - **`sweep` folders**: GPU time against misclassified pixels per scene with its Pareto
//!   front, each point's settings and images on a click;
//! - **`stability` folders**: the thresholds judged and the charts.

mod html;
mod scan;
mod sections;
mod sweep;

pub use scan::{scan, CompareRun, Found, GoldenFailure, StabilityRun, SweepRun};
pub use sweep::image_path as sweep_image_path;

use std::path::{Path, PathBuf};

/// A report that could not be made.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// The folder to report on is not a folder.
    #[error("{0}: not a folder")]
    NotAFolder(PathBuf),
    /// A file or folder could not be read or written.
    #[error("{0}: {1}")]
    Io(PathBuf, String),
    /// A JSON file is not what its name says.
    #[error("{0}: {1}")]
    Format(PathBuf, String),
    /// The folder holds more entries than a report reads.
    #[error("{0}: more than {1} entries; point the report at the output folder itself")]
    TooLarge(PathBuf, usize),
}

impl ReportError {
    pub(crate) fn io(p: &Path, e: std::io::Error) -> ReportError {
        ReportError::Io(p.to_path_buf(), e.to_string())
    }
}

/// What a written report holds.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Summary {
    /// The page.
    pub path: PathBuf,
    /// Failed goldens.
    pub goldens: usize,
    /// `compare` folders.
    pub compares: usize,
    /// `sweep` folders.
    pub sweeps: usize,
    /// `stability` folders.
    pub stabilities: usize,
    /// The page's size.
    pub bytes: usize,
}

impl std::fmt::Display for Summary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}: {} failed golden(s), {} compare, {} sweep, {} stability ({:.1} MiB)",
            self.path.display(),
            self.goldens,
            self.compares,
            self.sweeps,
            self.stabilities,
            self.bytes as f64 / (1024.0 * 1024.0)
        )
    }
}

/// The page for what `found` holds under `root`.
pub fn html(root: &Path, found: &Found) -> Result<String, ReportError> {
    let mut body = String::new();
    let mut nav = Vec::new();
    // Failed goldens always have their section (saying none failed); the others only when found.
    let mut section = |id: &str, title: &str, n: usize, inner: String| {
        if n == 0 && id != "goldens" {
            return;
        }
        nav.push(format!("<a href=\"#{id}\">{title} ({n})</a>"));
        body += &format!("<section id=\"{id}\"><h2>{title} ({n})</h2>{inner}</section>\n");
    };
    let mut goldens = articles(&found.goldens, |_, g| sections::golden(root, g))?;
    if found.goldens.is_empty() {
        goldens = "<p>No failed goldens: every golden under this folder matched when last \
                   checked (a match removes what a failure left).</p>"
            .into();
    }
    section("goldens", "Failed goldens", found.goldens.len(), goldens);
    let c = articles(&found.compares, |_, c| sections::compare(root, c))?;
    section("compare", "Compare", found.compares.len(), c);
    let s = articles(&found.sweeps, |n, run| sweep::sweep(root, n, run))?;
    section("sweep", "Sweep", found.sweeps.len(), s);
    let s = articles(&found.stabilities, |_, r| sections::stability(root, r))?;
    section("stability", "Stability", found.stabilities.len(), s);
    let title = format!("umbra report: {}", root.display());
    Ok(html::page(&title, &nav.join(""), &body))
}

/// The articles `one` makes of `items` (with each one's index), one after another.
fn articles<T>(
    items: &[T],
    one: impl Fn(usize, &T) -> Result<String, ReportError>,
) -> Result<String, ReportError> {
    let mut s = String::new();
    for (n, item) in items.iter().enumerate() {
        s += &one(n, item)?;
    }
    Ok(s)
}

/// Scans `root` and writes the page to `out` (`root/report.html` when None).
pub fn write(root: &Path, out: Option<&Path>) -> Result<Summary, ReportError> {
    let found = scan(root)?;
    let page = html(root, &found)?;
    let path = out.map_or_else(|| root.join("report.html"), Path::to_path_buf);
    std::fs::write(&path, &page).map_err(|e| ReportError::io(&path, e))?;
    Ok(Summary {
        path,
        goldens: found.goldens.len(),
        compares: found.compares.len(),
        sweeps: found.sweeps.len(),
        stabilities: found.stabilities.len(),
        bytes: page.len(),
    })
}
