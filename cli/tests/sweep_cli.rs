//! `umbra sweep` end to end (lavapipe, validation on): the quick grid on the demo at a small size
//! (its format replaced by `--formats d16`) writes the CSV, the JSON, the charts and with
//! `--report` the page, and a second run resumes from the CSV with nothing left to do.

use std::path::PathBuf;
use std::process::Command;

fn umbra(args: &[&str]) -> (bool, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_umbra"))
        .args(args)
        .output()
        .unwrap();
    (
        o.status.success(),
        format!(
            "{}{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        ),
    )
}

#[test]
fn quick_sweep_writes_rows_and_charts_and_resumes() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("sweep-cli");
    let _ = std::fs::remove_dir_all(&dir);
    let args = [
        "sweep",
        "demo",
        "--quick",
        "--formats",
        "d16",
        "--size",
        "96x54",
        "--repeat",
        "1",
        "--views",
        "1",
        "--out",
        dir.to_str().unwrap(),
        "--validation",
    ];
    let (ok, log) = umbra(&[&args[..], &["--report"]].concat());
    assert!(ok, "{log}");
    assert!(log.contains("swept 48 run(s)"), "{log}");
    // --report: the page, a point per configuration, and each point's image (saved by
    // --images, which --report implies) inlined beside its settings.
    assert!(
        log.contains("report.html: 0 failed golden(s), 0 compare, 1 sweep, 0 stability"),
        "{log}"
    );
    let page = std::fs::read_to_string(dir.join("report.html")).unwrap();
    assert_eq!(page.matches("<circle data-point=").count(), 48);
    assert_eq!(page.matches("<div class=\"point\"").count(), 48);
    assert_eq!(page.matches("data:image/png;base64,").count(), 48);
    let images = std::fs::read_dir(dir.join("images/demo"))
        .unwrap()
        .flat_map(|v| std::fs::read_dir(v.unwrap().path()).unwrap())
        .count();
    assert_eq!(images, 48);
    let csv = std::fs::read_to_string(dir.join("sweep.csv")).unwrap();
    assert_eq!(csv.lines().count(), 49, "header + 48 rows");
    assert!(csv.starts_with("scene,view,config,method,filter,format,bias,map_texels"));
    assert!(
        csv.lines()
            .skip(1)
            .all(|l| l.split(',').nth(5) == Some("d16")),
        "every row D16"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("sweep.json")).unwrap()).unwrap();
    assert_eq!(json["schema"], "umbra-sweep/1");
    assert_eq!(json["rows"].as_array().unwrap().len(), 48);
    for f in [
        "pareto.svg",
        "pareto.png",
        "pareto-demo.svg",
        "pareto-demo.png",
    ] {
        assert!(dir.join(f).metadata().unwrap().len() > 1000, "{f}");
    }
    // Resume: everything is in the CSV already.
    let (ok, log) = umbra(&args);
    assert!(ok, "{log}");
    assert!(
        log.contains("swept 0 run(s)") && log.contains("48 already"),
        "{log}"
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("sweep.csv"))
            .unwrap()
            .lines()
            .count(),
        49
    );
}

#[test]
fn compare_writes_its_json_and_report() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("compare-cli");
    let _ = std::fs::remove_dir_all(&dir);
    let (ok, log) = umbra(&[
        "compare",
        "--size",
        "96x72",
        "--out",
        dir.to_str().unwrap(),
        "--report",
        "--validation",
    ]);
    assert!(ok, "{log}");
    let line = log.lines().find(|l| l.starts_with('{')).unwrap();
    let printed: serde_json::Value = serde_json::from_str(line).unwrap();
    let written: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("compare.json")).unwrap()).unwrap();
    assert_eq!(printed, written);
    assert!(
        log.contains("report.html: 0 failed golden(s), 1 compare"),
        "{log}"
    );
    let page = std::fs::read_to_string(dir.join("report.html")).unwrap();
    // The figures as a table (the misclassified fraction as printed, to 4 figures) and the
    // three compared images with the extra figures.
    let mis = written["misclassified"].as_f64().unwrap();
    let shown: f64 = page
        .split("<th>misclassified</th><td>")
        .nth(1)
        .and_then(|s| s.split('<').next())
        .and_then(|s| s.parse().ok())
        .unwrap();
    assert!((shown - mis).abs() <= 1e-3 * mis, "{shown} against {mis}");
    assert!(page.matches("data:image/png;base64,").count() >= 5);
}
