//! The report's sections for failed goldens, `compare` folders and `stability` folders (the
//! sweep's, with its chart, in `sweep`).

use super::html::{comparator, esc, figure, table};
use super::scan::{CompareRun, GoldenFailure, StabilityRun};
use super::ReportError;
use serde_json::Value;
use std::path::Path;

/// `p` relative to the report's folder, for headings.
pub(crate) fn rel(root: &Path, p: &Path) -> String {
    match p.strip_prefix(root) {
        Ok(r) if r.as_os_str().is_empty() => root.display().to_string(),
        Ok(r) => r.display().to_string(),
        Err(_) => p.display().to_string(),
    }
}

/// A JSON value as table text: numbers to 4 significant figures, strings as they are, the rest
/// as compact JSON.
pub(crate) fn value_text(v: &Value) -> String {
    match v {
        Value::Number(n) => match (n.as_i64(), n.as_f64()) {
            (Some(i), _) => i.to_string(),
            (None, Some(f)) => num(f),
            _ => n.to_string(),
        },
        Value::String(s) => s.clone(),
        Value::Null => "–".into(),
        other => other.to_string(),
    }
}

/// `f` to 4 significant figures (exponent form below 1e-3).
pub(crate) fn num(f: f64) -> String {
    if f == 0.0 || !f.is_finite() {
        return format!("{f}");
    }
    if f.abs() < 1e-3 || f.abs() >= 1e6 {
        return format!("{f:.3e}");
    }
    let digits = (3 - f.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{f:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// One failed golden: the reason, the figures against the tolerance, the comparator over the
/// lit images and, where kept, over the shadow views.
pub(crate) fn golden(root: &Path, g: &GoldenFailure) -> Result<String, ReportError> {
    let mut s = format!(
        "<article class=\"golden\"><h3>{}</h3>",
        esc(&rel(root, &g.golden))
    );
    match &g.failure {
        Some(f) => {
            s += &format!(
                "<p class=\"reason\">{}</p>",
                esc(f["reason"].as_str().unwrap_or(""))
            );
            let (fig, tol) = (&f["figures"], &f["tolerance"]);
            let pair = |k: &str, t: &str| {
                format!(
                    "{} (allowed {})",
                    esc(&value_text(&fig[k])),
                    esc(&value_text(&tol[t]))
                )
            };
            s += &table(&[
                ("device class".into(), esc(&value_text(&f["device_class"]))),
                (
                    "pixels differing".into(),
                    format!(
                        "{} of {}",
                        value_text(&fig["differing"]),
                        value_text(&fig["pixels"])
                    ),
                ),
                ("mean FLIP".into(), pair("mean_flip", "mean_flip")),
                (
                    format!("pixels over FLIP {}", value_text(&fig["pixel_flip"])),
                    pair("pixels_over", "pixels_over"),
                ),
                (
                    "shadow verdicts changed".into(),
                    pair("shadow_changes", "shadow_changes"),
                ),
                (
                    "of them now in shadow".into(),
                    esc(&value_text(&fig["now_in_shadow"])),
                ),
            ]);
        }
        None => s += "<p class=\"note\">no NAME.failure.json beside it: the images only</p>",
    }
    let mut more = Vec::new();
    if let Some(d) = &g.diff {
        more.push((d.as_path(), "FLIP difference (black equal, yellow far)"));
    }
    s += &comparator((&g.golden, "golden"), (&g.actual, "actual"), &more)?;
    if let Some([gs, as_, sd]) = &g.shadow {
        s += "<h4>Shadow views (255 lit, 0 in shadow)</h4>";
        s += &comparator(
            (gs, "golden shadow view"),
            (as_, "actual shadow view"),
            &[(sd, "verdicts changed: red now in shadow, blue now lit")],
        )?;
    }
    Ok(s + "</article>")
}

/// One `compare` folder: its figures as a table and the GPU frame against the reference.
pub(crate) fn compare(root: &Path, c: &CompareRun) -> Result<String, ReportError> {
    let mut s = format!(
        "<article class=\"compare\"><h3>{}</h3>",
        esc(&rel(root, &c.dir))
    );
    match &c.json {
        Some(Value::Object(m)) => {
            let rows: Vec<(String, String)> = m
                .iter()
                .filter(|(_, v)| !v.is_array() || v.as_array().is_some_and(|a| a.len() <= 8))
                .map(|(k, v)| (k.clone(), esc(&value_text(v))))
                .collect();
            s += &table(&rows);
        }
        _ => s += "<p class=\"note\">no compare.json in this folder: the images only</p>",
    }
    let dir = &c.dir;
    s += &comparator(
        (&dir.join("reference.png"), "reference (ray cast)"),
        (&dir.join("gpu.png"), "GPU"),
        &[(
            &dir.join("diff.png"),
            "diff: red false shadow, blue false light",
        )],
    )?;
    let mut extra = String::new();
    for (f, cap) in [
        ("shadow.png", "GPU shadow view"),
        ("coverage.png", "reference: visible fraction of the light"),
        ("depth_profile.png", "misclassified along view depth"),
    ] {
        let p = dir.join(f);
        if p.is_file() {
            extra += &figure(&p, cap, "x")?;
        }
    }
    if !extra.is_empty() {
        s += &format!("<div class=\"charts\">{extra}</div>");
    }
    Ok(s + "</article>")
}

/// One `stability` folder: the thresholds judged and the charts.
pub(crate) fn stability(root: &Path, r: &StabilityRun) -> Result<String, ReportError> {
    let j = &r.json;
    let verdicts = j["verdicts"].as_array().cloned().unwrap_or_default();
    let failed = verdicts.iter().filter(|v| v["pass"] == false).count();
    let mut s = format!(
        "<article class=\"stability\"><h3>{}: {}, {} on {}</h3><p>{} of {} thresholds met</p>",
        esc(&rel(root, &r.dir)),
        esc(&value_text(&j["scene"])),
        esc(&value_text(&j["size"])),
        esc(&value_text(&j["device"])),
        verdicts.len() - failed,
        verdicts.len()
    );
    s += "<table><tr><th>criterion</th><th>measured</th><th>verdict</th></tr>";
    for v in &verdicts {
        let (class, word) = match v["pass"].as_bool() {
            Some(true) => ("pass", "pass"),
            Some(false) => ("fail", "FAIL"),
            None => ("na", "n/a"),
        };
        s += &format!(
            "<tr><td>{}</td><td>{}</td><td class=\"{class}\">{word}</td></tr>",
            esc(&value_text(&v["criterion"])),
            esc(&value_text(&v["measured"]))
        );
    }
    s += "</table><div class=\"charts\">";
    for c in &r.charts {
        let name = c.file_stem().unwrap_or_default().to_string_lossy();
        s += &figure(c, &name, "x")?;
    }
    Ok(s + "</div></article>")
}

#[cfg(test)]
mod tests {
    #[test]
    fn numbers_keep_four_significant_figures_and_no_trailing_zeros() {
        let cases = [
            (0.005, "0.005"),
            (1.0, "1"),
            (123.456, "123.5"),
            (0.0194321, "0.01943"),
        ];
        for (f, s) in cases {
            assert_eq!(super::num(f), s);
        }
        assert_eq!(super::num(2.5e-5), "2.500e-5");
    }
}
