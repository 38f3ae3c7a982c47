//! The viewer's panel and file handling under Xvfb on lavapipe, validation on, driven by
//! `--script`: the panel shows and hides (`F1`) and screenshots leave it out unless asked; a
//! setting changed through a panel widget (clicked through egui's own input) draws the frame its
//! key draws; picking fills the panel; a dropped file opens, a file changed on disk reloads, and
//! a broken one keeps the scene on screen with its error.

use crate::common::gltf_builder::{Builder, Container};
use crate::common::image_diff;
use crate::xvfb::{out, umbra, Xvfb};
use serde_json::json;
use std::path::{Path, PathBuf};

const SIZE: &str = "640x360";

/// A run of the viewer on the demo (or `model`) for `frames` frames with `script`, saving its
/// last frame to `shot`; panics with the log on failure.
fn view(x: &Xvfb, model: Option<&Path>, script: &str, shot: &Path, extra: &[&str]) -> String {
    let mut args = vec![
        "view".to_string(),
        "--size".into(),
        SIZE.into(),
        "--frames".into(),
        "8".into(),
        "--screenshot".into(),
        shot.to_str().unwrap().into(),
        "--no-vsync".into(),
        "--validation".into(),
    ];
    if let Some(m) = model {
        args.insert(1, m.to_str().unwrap().into());
    }
    if !script.is_empty() {
        args.extend(["--script".into(), script.into()]);
    }
    args.extend(extra.iter().map(|s| s.to_string()));
    let args: Vec<&str> = args.iter().map(|s| s.as_str()).collect();
    let (ok, log) = umbra(&args, Some(&x.display));
    assert!(ok, "viewer failed ({script}):\n{log}");
    log
}

fn open(p: &Path) -> image::RgbaImage {
    image::open(p).unwrap().to_rgba8()
}

#[test]
fn the_panel_shows_and_hides_and_screenshots_leave_it_out() {
    let x = Xvfb::start();
    let scene = out("panel_scene.png");
    let with_ui = out("panel_with_ui.png");
    let hidden = out("panel_hidden_ui.png");
    view(&x, None, "", &scene, &[]);
    let log = view(&x, None, "", &with_ui, &["--screenshot-ui"]);
    assert!(!log.contains("panel: hidden"), "{log}");
    let log = view(&x, None, "key:f1", &hidden, &["--screenshot-ui"]);
    assert!(log.contains("panel: hidden"), "{log}");
    let (scene, with_ui, hidden) = (open(&scene), open(&with_ui), open(&hidden));
    // Hidden, the screen is the scene; shown, the panel covers the right of it.
    assert_eq!(
        image_diff(&scene, &hidden).differing(),
        0,
        "the hidden panel left marks"
    );
    let (w, h) = scene.dimensions();
    let (mut left, mut right) = (0, 0);
    for (x, y, p) in with_ui.enumerate_pixels() {
        if p != scene.get_pixel(x, y) {
            if x < w / 2 {
                left += 1;
            } else {
                right += 1;
            }
        }
    }
    eprintln!("panel pixels: {right} on the right half, {left} on the left");
    // Measured: 113,040 pixels of the right half (the panel, 260 points wide and more as its
    // rows need), none on the left.
    assert!(
        right > (w * h / 5) as usize && left == 0,
        "right {right}, left {left}"
    );
}

#[test]
fn a_panel_widget_draws_what_its_key_draws() {
    let x = Xvfb::start();
    let by_key = out("panel_key_pcf.png");
    let by_widget = out("panel_widget_pcf.png");
    let untouched = out("panel_untouched.png");
    // K once: the 2×2 kernel becomes 3×3; the panel's 3×3 button sets the same. And the map
    // size: `]` and the 4096 button.
    let key_log = view(&x, None, "key:k,key:]", &by_key, &[]);
    let ui_log = view(&x, None, "ui:pcf.3x3,ui:map.4096", &by_widget, &[]);
    view(&x, None, "", &untouched, &[]);
    for log in [&key_log, &ui_log] {
        assert!(log.contains("PCF: P3x3"), "{log}");
        assert!(log.contains("shadow map: 4096x4096"), "{log}");
    }
    let (a, b, c) = (open(&by_key), open(&by_widget), open(&untouched));
    assert_eq!(
        image_diff(&a, &b).differing(),
        0,
        "the widget and the key drew different frames"
    );
    let changed = image_diff(&a, &c).differing();
    eprintln!("3x3 filter and 4096² map: {changed} pixels differ from the defaults");
    // Measured: 224 pixels (the shadow edges) move.
    assert!(changed > 150, "{changed} pixels changed");
    // A widget the panel does not have is an error, not a silent step.
    let (ok, log) = umbra(
        &[
            "view",
            "--size",
            SIZE,
            "--frames",
            "4",
            "--no-vsync",
            "--script",
            "ui:nonsense",
        ],
        Some(&x.display),
    );
    assert!(!ok && log.contains("no such widget"), "{log}");
}

/// Two flat, unlit quads facing +Z, 1.4 units apart: a model to pick and to swap.
fn panels(dir: &Path, name: &str, rgb: [f32; 3]) -> PathBuf {
    let mut b = Builder::default();
    b.use_extension("KHR_materials_unlit");
    let mat = b.material(json!({"name": "flat",
        "pbrMetallicRoughness": {"baseColorFactor": [rgb[0], rgb[1], rgb[2], 1.0]},
        "extensions": {"KHR_materials_unlit": {}}}));
    let mesh = b.quad("panel", 1.0, 1.0, mat);
    for (i, x) in [-0.7f32, 0.7].into_iter().enumerate() {
        b.node(
            json!({"name": format!("panel {i}"), "mesh": mesh, "translation": [x, 0.0, 0.0]}),
            true,
        );
    }
    b.write(dir, name, Container::Glb)
}

/// The colour at the middle of the left quad (head-on from 3 units, 45°: 144.9 px a unit, so
/// 101 px left of the centre of a 640×360 window, clear of the panel on the right).
fn left_quad(img: &image::RgbaImage) -> [u8; 4] {
    img.get_pixel(219, 180).0
}

const HEAD_ON: [&str; 2] = ["--eye=0,0,3", "--target=0,0,0"];

#[test]
fn picking_fills_the_panel() {
    let dir = out("panel_pick");
    let model = panels(&dir, "picked", [0.2, 0.6, 0.9]);
    let x = Xvfb::start();
    let before = out("panel_pick_before.png");
    let after = out("panel_pick_after.png");
    let mut extra = vec!["--screenshot-ui"];
    extra.extend(HEAD_ON);
    view(&x, Some(&model), "", &before, &extra);
    let log = view(&x, Some(&model), "click:219:180", &after, &extra);
    assert!(
        log.contains("pick: pixel (219, 180): node 0 'panel 0'"),
        "{log}"
    );
    // The panel (right third) shows the report; the picked quad is tinted.
    let (a, b) = (open(&before), open(&after));
    let panel_changed = a
        .enumerate_pixels()
        .filter(|(x, y, p)| *x >= 400 && *p != b.get_pixel(*x, *y))
        .count();
    eprintln!("pick: {panel_changed} panel pixels changed");
    // Measured: 1,194 (the report's lines).
    assert!(panel_changed > 800, "{panel_changed} panel pixels changed");
    assert_ne!(
        left_quad(&a),
        left_quad(&b),
        "the picked quad is not tinted"
    );
}

#[test]
fn a_dropped_or_changed_file_reloads_and_a_broken_one_keeps_the_scene() {
    let dir = out("panel_reload");
    let red = panels(&dir, "red", [1.0, 0.0, 0.0]);
    let blue = panels(&dir, "blue", [0.0, 0.0, 1.0]);
    let broken = dir.join("broken.glb");
    std::fs::write(&broken, b"glTF not really").unwrap();
    let x = Xvfb::start();
    // Dropped: the blue model replaces the red one.
    let shot = out("panel_dropped.png");
    let script = format!("drop:{}", blue.display());
    let log = view(&x, Some(&red), &script, &shot, &HEAD_ON);
    assert!(log.contains("opened:") && log.contains("blue.glb"), "{log}");
    let p = left_quad(&open(&shot));
    assert!(p[2] > 200 && p[0] < 30, "not blue after the drop: {p:?}");
    // A broken file: one line, the red model stays.
    let shot = out("panel_broken.png");
    let script = format!("drop:{}", broken.display());
    let log = view(&x, Some(&red), &script, &shot, &HEAD_ON);
    let line = log.lines().find(|l| l.starts_with("load: ")).unwrap_or("");
    assert!(
        line.contains("broken.glb") && line.ends_with("keeping red.glb"),
        "{log}"
    );
    let p = left_quad(&open(&shot));
    assert!(
        p[0] > 200 && p[2] < 30,
        "not red after the broken drop: {p:?}"
    );
    // Changed on disk: the watcher sees the blue file copied over the red one and reloads.
    let watched = dir.join("watched.glb");
    std::fs::copy(&red, &watched).unwrap();
    let shot = out("panel_changed.png");
    let script = format!("copy:{}>{},wait:reload", blue.display(), watched.display());
    let log = view(&x, Some(&watched), &script, &shot, &HEAD_ON);
    assert!(
        log.contains("reloaded:") && log.contains("watched.glb"),
        "{log}"
    );
    let p = left_quad(&open(&shot));
    assert!(p[2] > 200 && p[0] < 30, "not blue after the reload: {p:?}");
}
