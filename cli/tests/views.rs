//! `render --views`: a batch of poses of the demo on lavapipe, validation on. Each view's image
//! and `.npy` outputs are written; the shared map is drawn once; with `--per-view-shadows` each
//! image is the same to the byte as a single `render --eye --target` of that pose.

use std::path::{Path, PathBuf};
use std::process::Command;

fn umbra(args: &[&str], dir: &Path) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_umbra"))
        .args(args)
        .current_dir(dir)
        .env("UMBRA_VALIDATION", "1")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{args:?}: {stderr}");
    assert!(!stderr.contains("validation"), "{stderr}");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The values of a little-endian 4-byte `.npy` array and its shape.
fn npy(path: &Path) -> (Vec<[u8; 4]>, String) {
    let b = std::fs::read(path).unwrap();
    assert_eq!(&b[..8], b"\x93NUMPY\x01\x00");
    let len = u16::from_le_bytes([b[8], b[9]]) as usize;
    let header = String::from_utf8_lossy(&b[10..10 + len]).into_owned();
    assert_eq!((10 + len) % 64, 0, "{header}");
    let shape = header
        .split("'shape': ")
        .nth(1)
        .and_then(|s| s.split(')').next())
        .unwrap()
        .to_string()
        + ")";
    let data = b[10 + len..]
        .chunks_exact(4)
        .map(|c| [c[0], c[1], c[2], c[3]])
        .collect();
    (data, shape)
}

const EYES: [[f32; 3]; 3] = [[6.0, 4.0, 6.0], [-6.0, 4.0, 6.0], [0.0, 5.0, -7.0]];

#[test]
fn a_batch_of_views_writes_every_output_and_draws_its_map_once() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("views");
    std::fs::create_dir_all(&dir).unwrap();
    let poses: Vec<_> = EYES
        .iter()
        .map(|e| serde_json::json!({"eye": e, "target": [0.0, 0.5, 0.0]}))
        .collect();
    std::fs::write(
        dir.join("poses.json"),
        serde_json::to_string(&poses).unwrap(),
    )
    .unwrap();
    // The projection comes from the other options: --eye/--target's (45°, near 10⁻⁴ of the
    // scene's diagonal), as the single renders below have it.
    let size = ["--size", "160x120", "--eye", "1,1,1", "--target", "0,0,0"];
    let out = umbra(
        &[
            &["render", "--views", "poses.json", "-o", "v_%02d.png"][..],
            &size[..],
            &["--outputs", "color,depth,segmentation,normals"],
        ]
        .concat(),
        &dir,
    );
    assert!(out.contains("shadow pass drawn in 1 of 3"), "{out}");
    for (k, e) in EYES.iter().enumerate() {
        let png = dir.join(format!("v_{k:02}.png"));
        assert_eq!(
            image::open(&png).unwrap().to_rgba8().dimensions(),
            (160, 120)
        );
        let (depth, shape) = npy(&dir.join(format!("v_{k:02}.depth.npy")));
        assert_eq!(shape, "(120, 160)");
        let depth: Vec<f32> = depth.into_iter().map(f32::from_le_bytes).collect();
        // The target, 0.5 above the ground at the image's centre, lies along the view axis.
        let eye = glam::Vec3::from_array(*e);
        let expect = eye.distance(glam::Vec3::new(0.0, 0.5, 0.0));
        let centre = depth[60 * 160 + 80];
        assert!(
            centre > 0.0 && centre <= expect * 1.05,
            "view {k}: {centre} vs {expect}"
        );
        let (ids, shape) = npy(&dir.join(format!("v_{k:02}.segmentation.npy")));
        assert_eq!(shape, "(120, 160)");
        assert!(ids.iter().any(|b| u32::from_le_bytes(*b) > 0));
        let (normals, shape) = npy(&dir.join(format!("v_{k:02}.normals.npy")));
        assert_eq!(shape, "(120, 160, 3)");
        assert_eq!(normals.len(), 160 * 120 * 3);
    }
    // Fitted per view, each image is a single render's.
    let out = umbra(
        &[
            &[
                "render",
                "--views",
                "poses.json",
                "-o",
                "p_%02d.png",
                "--per-view-shadows",
            ][..],
            &size[..],
        ]
        .concat(),
        &dir,
    );
    assert!(out.contains("per view"), "{out}");
    for (k, e) in EYES.iter().enumerate() {
        let eye = format!("{},{},{}", e[0], e[1], e[2]);
        let one = format!("one_{k}.png");
        umbra(
            &[
                "render", "--size", "160x120", "--eye", &eye, "--target", "0,0.5,0", "-o", &one,
            ],
            &dir,
        );
        let a = image::open(dir.join(&one)).unwrap().to_rgba8();
        let b = image::open(dir.join(format!("p_{k:02}.png")))
            .unwrap()
            .to_rgba8();
        assert!(
            a == b,
            "view {k}: the batch's image differs from a single render"
        );
    }
}
