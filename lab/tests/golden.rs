//! `umbra::golden` (feature `golden`): a frame against its stored golden, blessing, the device
//! class's folder and its fallback, and the shadow-aware verdict, on the demo scene.
//!
//! The shadow verdict count is checked against a count made here from the two shadow views.

use crate::common::*;
use glam::Vec3;
use std::path::{Path, PathBuf};
use umbra::golden::{check_frame, device_class, Bless, Capture, Outcome, Tolerance};
use umbra::{demo_scene, Renderer, View};

const W: u32 = 160;
const H: u32 = 120;

/// An empty folder for one test's goldens.
fn fresh(name: &str) -> PathBuf {
    let d = out_dir().join("golden").join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn demo_view() -> View {
    View::new(demo_scene().default_camera(W as f32 / H as f32))
}

fn capture(r: &mut Renderer, view: &View) -> Capture {
    Capture::render(r, view, W, H).unwrap()
}

#[test]
fn blessing_policy_from_the_environment_values() {
    let cases = [
        (None, None, Bless::Off),
        (Some("0"), None, Bless::Off),
        (Some(""), Some("true"), Bless::Off),
        (None, Some("true"), Bless::Off),
        (Some("1"), None, Bless::On),
        (Some("1"), Some("false"), Bless::On),
        (Some("1"), Some("0"), Bless::On),
        (Some("1"), Some("true"), Bless::RefusedUnderCi),
        (Some("yes"), Some("1"), Bless::RefusedUnderCi),
    ];
    for (bless, ci, want) in cases {
        assert_eq!(Bless::from_values(bless, ci), want, "{bless:?} {ci:?}");
    }
}

#[test]
fn a_missing_golden_fails_is_blessed_into_its_class_folder_and_then_matches() {
    let dir = fresh("bless");
    let golden = dir.join("demo.png");
    let ctx = context();
    let mut r = Renderer::new(&ctx, &demo_scene()).unwrap();
    let class = device_class(&ctx);
    if ctx.device_name.contains("llvmpipe") {
        assert_eq!(class, "lavapipe");
    }
    let classed = dir.join(&class).join("demo.png");
    let first = capture(&mut r, &demo_view());

    let missing = check_frame(&first, &golden, Tolerance::EXACT, Bless::Off).unwrap_err();
    assert!(
        missing.reason.contains("UMBRA_BLESS=1") && missing.reason.contains(&class),
        "{}",
        missing.reason
    );
    let refused = check_frame(&first, &golden, Tolerance::EXACT, Bless::RefusedUnderCi);
    assert!(refused.unwrap_err().reason.contains("refused under CI"));
    assert!(!classed.exists(), "nothing written before blessing");

    let blessed = check_frame(&first, &golden, Tolerance::EXACT, Bless::On).unwrap();
    assert_eq!(
        blessed,
        Outcome::Blessed {
            path: classed.clone(),
            replaced: None
        }
    );
    assert_eq!(image::open(&classed).unwrap().to_rgba8(), first.lit);
    let shadow = image::open(dir.join(&class).join("demo.shadow.png")).unwrap();
    assert_eq!(Some(shadow.to_rgba8()), first.shadow);

    // A second frame of the same view on the same device: the same bytes.
    let again = capture(&mut r, &demo_view());
    match check_frame(&again, &golden, Tolerance::EXACT, Bless::Off) {
        Ok(Outcome::Matched(f)) => {
            assert_eq!((f.differing, f.shadow_changes), (0, Some((0, 0))), "{f:?}")
        }
        other => panic!("{other:?}"),
    }
    // Another size is a failure that names both.
    let small = Capture::render(&mut r, &demo_view(), W / 2, H / 2).unwrap();
    let m = check_frame(&small, &golden, Tolerance::EXACT, Bless::Off).unwrap_err();
    assert!(
        m.reason.contains("80x60") && m.reason.contains("160x120"),
        "{}",
        m.reason
    );
    drop(r);
}

#[test]
fn the_class_folder_comes_first_and_the_shared_golden_is_the_fallback() {
    let dir = fresh("fallback");
    let golden = dir.join("demo.png");
    let ctx = context();
    let mut r = Renderer::new(&ctx, &demo_scene()).unwrap();
    let c = capture(&mut r, &demo_view());
    let classed = dir.join(&c.device_class).join("demo.png");
    let black = image::RgbaImage::from_pixel(W, H, image::Rgba([0, 0, 0, 255]));
    // Only a shared golden: it is used.
    c.lit.save(&golden).unwrap();
    assert!(matches!(
        check_frame(&c, &golden, Tolerance::EXACT, Bless::Off),
        Ok(Outcome::Matched(_))
    ));
    // A wrong golden in the class folder wins over the right shared one.
    std::fs::create_dir_all(classed.parent().unwrap()).unwrap();
    black.save(&classed).unwrap();
    let m = check_frame(&c, &golden, Tolerance::EXACT, Bless::Off).unwrap_err();
    assert!(
        m.reason.starts_with(&classed.display().to_string()),
        "{}",
        m.reason
    );
    assert!(m.written.iter().all(|p| p.parent() == classed.parent()));
    drop(r);
}

/// Pixels whose verdict (visibility ≥ 0.5) differs between two shadow views, counted here.
fn verdicts_changed(a: &Path, b: &image::RgbaImage) -> usize {
    let a = image::open(a).unwrap().to_rgba8();
    a.pixels()
        .zip(b.pixels())
        .filter(|(p, q)| (p[0] >= 128) != (q[0] >= 128))
        .count()
}

#[test]
fn a_failure_says_apart_what_changed_in_the_shadows_and_in_the_shading() {
    let dir = fresh("verdict");
    let golden = dir.join("demo.png");
    let ctx = context();
    let mut r = Renderer::new(&ctx, &demo_scene()).unwrap();
    let base = demo_view();
    let c = capture(&mut r, &base);
    check_frame(&c, &golden, Tolerance::EXACT, Bless::On).unwrap();
    let stored_shadow = dir.join(&c.device_class).join("demo.shadow.png");

    // The sun turned by 20°: shadows move.
    let sun = demo_scene().lights[0].direction;
    let turned = glam::Quat::from_rotation_y(20f32.to_radians()) * sun;
    let moved = capture(
        &mut r,
        &View {
            sun_direction: Some(turned),
            ..base.clone()
        },
    );
    let tol = Tolerance::close((W * H) as usize);
    let m = check_frame(&moved, &golden, tol, Bless::Off).unwrap_err();
    let (n, dark) = m.figures.unwrap().shadow_changes.unwrap();
    let counted = verdicts_changed(&stored_shadow, moved.shadow.as_ref().unwrap());
    eprintln!("sun turned 20°: {}", m.reason);
    assert_eq!(n, counted);
    assert!(n > tol.shadow_changes && dark <= n, "{n} {dark}");
    assert!(
        m.reason.contains("changed their shadow verdict"),
        "{}",
        m.reason
    );
    let names: Vec<String> = m
        .written
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        names,
        [
            "demo.actual.png",
            "demo.diff.png",
            "demo.actual.shadow.png",
            "demo.shadow-diff.png",
            "demo.failure.json"
        ]
    );
    let json: serde_json::Value = serde_json::from_slice(
        &std::fs::read(dir.join(&c.device_class).join("demo.failure.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(json["reason"], m.reason.as_str());
    assert_eq!(json["figures"]["shadow_changes"], n);
    for p in m.written.iter().filter(|p| p.extension().unwrap() == "png") {
        assert_eq!(
            image::open(p).unwrap().to_rgb8().dimensions(),
            (W, H),
            "{p:?}"
        );
    }

    // Brighter ambient light: the shading changes, no shadow verdict does.
    let brighter = capture(
        &mut r,
        &View {
            ambient: Some(Vec3::splat(0.6)),
            ..base.clone()
        },
    );
    let m = check_frame(&brighter, &golden, tol, Bless::Off).unwrap_err();
    eprintln!("ambient 0.6: {}", m.reason);
    let f = m.figures.unwrap();
    assert_eq!(f.shadow_changes, Some((0, 0)));
    assert!(
        f.mean_flip > tol.mean_flip && f.pixels_over > tol.pixels_over,
        "{f:?}"
    );
    assert!(
        m.reason.contains("shadows within tolerance") && m.reason.contains("shading changed"),
        "{}",
        m.reason
    );
    // Blessing replaces a failing golden and says what it replaced.
    match check_frame(&brighter, &golden, tol, Bless::On) {
        Ok(Outcome::Blessed {
            replaced: Some(r), ..
        }) => assert_eq!(r, f),
        other => panic!("{other:?}"),
    }
    assert!(check_frame(&brighter, &golden, Tolerance::EXACT, Bless::Off).is_ok());
    // What the failures left is gone once the golden matches (a report would show it).
    for p in &m.written {
        assert!(!p.exists(), "{p:?} left after a match");
    }
    drop(r);
}

/// The project's own frames against goldens kept in `lab/tests/golden/lavapipe/` (blessed with
/// `UMBRA_BLESS=1 cargo test -p umbra-lab --test lab -- own_frames`, looked at, committed): the
/// demo, and the skinned bar (written by the tests' own code) over a ground at three times of
/// its animation. A golden is the right check here: these frames are what a change to shading,
/// shadows or skinning moves, and the reference and analytic tests judge them elsewhere.
/// `Tolerance::close`: another build of lavapipe may round a few pixels apart (ten renders here
/// are identical to the byte: docs/golden.md).
#[test]
fn own_frames_match_their_goldens() {
    let ctx = context();
    let class = device_class(&ctx);
    if class != "lavapipe" {
        eprintln!("goldens are kept for lavapipe; {class} has none: nothing compared");
        return;
    }
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden");
    let (w, h) = (240, 160);
    let tol = Tolerance::close((w * h) as usize);
    let mut failed = Vec::new();
    let mut check = |c: &Capture, name: &str| match check_frame(
        c,
        dir.join(format!("{name}.png")),
        tol,
        Bless::from_env(),
    ) {
        Ok(Outcome::Matched(f)) => eprintln!("{name}: matched, {} pixels differ", f.differing),
        Ok(o) => eprintln!("{name}: {o:?}"),
        Err(m) => failed.push(m.reason),
    };
    let mut r = Renderer::new(&ctx, &demo_scene()).unwrap();
    let view = View::new(demo_scene().default_camera(w as f32 / h as f32));
    check(&Capture::render(&mut r, &view, w, h).unwrap(), "demo");
    drop(r);
    let path = crate::common::animated::skinned_bar(&fresh("own-bar"), "bar", 0.0, true);
    let mut v = View::new(umbra::scene::Camera::look_at(
        Vec3::new(1.5, 2.0, 6.0),
        Vec3::new(0.0, 1.0, 0.0),
        45f32.to_radians(),
        0.05,
    ));
    v.sun_direction = Some(Vec3::new(-0.6, -1.0, -0.45));
    for t in [0.0, 0.5, 1.0] {
        let mut scene = umbra::scene::gltf::load_gltf(&path).unwrap();
        umbra::scene::built::shapes::add_ground(&mut scene);
        scene.pose_at(&umbra::scene::anim::Playing::One(0), t);
        let mut r = Renderer::new(&ctx, &scene).unwrap();
        check(
            &Capture::render(&mut r, &v, w, h).unwrap(),
            &format!("bar_t{t}"),
        );
    }
    assert!(failed.is_empty(), "{}", failed.join("\n"));
    assert_validation_clean(&ctx);
}
