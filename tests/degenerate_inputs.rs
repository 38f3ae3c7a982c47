//! Degenerate but loadable input: documented fallbacks with warnings, never a panic or a
//! validation message (lavapipe, validation on).

use crate::common::*;
use base64::Engine as _;
use serde_json::json;
use std::path::PathBuf;
use umbra::plan::View;
use umbra::render::Renderer;
use umbra::scene::gltf::load_gltf;

fn write_gltf(
    name: &str,
    positions: &[[f32; 3]],
    indices: &[u16],
    extra: impl FnOnce(&mut serde_json::Value),
) -> PathBuf {
    let mut data = Vec::new();
    for p in positions {
        for c in p {
            data.extend(c.to_le_bytes());
        }
    }
    let vlen = data.len();
    for i in indices {
        data.extend(i.to_le_bytes());
    }
    while data.len() % 4 != 0 {
        data.push(0);
    }
    let mut j = json!({
        "asset": {"version": "2.0"},
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"byteLength": data.len(), "uri": format!("data:application/octet-stream;base64,{}", base64::engine::general_purpose::STANDARD.encode(&data))}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": vlen}, {"buffer": 0, "byteOffset": vlen, "byteLength": indices.len() * 2}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": positions.len(), "type": "VEC3", "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 1.0]},
            {"bufferView": 1, "componentType": 5123, "count": indices.len(), "type": "SCALAR"}
        ]
    });
    extra(&mut j);
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("degenerate");
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, j.to_string()).unwrap();
    p
}

fn render_clean(scene: &umbra::scene::Scene) -> image::RgbaImage {
    render_clean_with_plan(scene).0
}

/// `render_clean`, with the plan the frame was drawn with.
fn render_clean_with_plan(scene: &umbra::scene::Scene) -> (image::RgbaImage, umbra::FramePlan) {
    let ctx = context();
    let mut r = Renderer::new(&ctx, scene).unwrap();
    let f = r
        .render(&View::new(scene.default_camera(1.0)), 64, 64)
        .unwrap();
    assert_validation_clean(&ctx);
    (f.image, f.plan)
}

#[test]
fn nan_positions_and_zero_area_triangles_are_dropped_or_kept_with_warnings() {
    let p = write_gltf(
        "nan.gltf",
        &[
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [f32::NAN, 0.0, 0.0],
            [1.0, 1.0, 1.0],
            [2.0, 2.0, 2.0],
        ],
        &[0, 1, 2, 3, 4, 5, 0, 0, 1],
        |_| {},
    );
    let s = load_gltf(&p).unwrap();
    let w = s
        .warnings
        .iter()
        .map(|w| format!("{} [{} {}]", w.message, w.code, w.pointer))
        .collect::<Vec<_>>()
        .join("\n");
    assert!(
        w.contains("1 triangles with non-finite positions dropped"),
        "{w}"
    );
    assert!(w.contains("1 zero-area triangles"), "{w}");
    assert!(w.contains("no normals; computed smooth normals"), "{w}");
    // Each with its code and the primitive's pointer (what `render` prints and `inspect` reports).
    for code in [
        "MESH_NONFINITE_POSITIONS",
        "MESH_DEGENERATE_TRIANGLES",
        "MESH_NORMALS_MISSING",
    ] {
        assert!(
            w.contains(&format!("[{code} /meshes/0/primitives/0]")),
            "{code}: {w}"
        );
    }
    assert_eq!(s.triangle_count(), 2);
    assert!(s.bounds().min.is_finite() && s.bounds().max.is_finite());
    render_clean(&s);
}

#[test]
fn normal_map_without_uvs_is_ignored_with_a_warning() {
    let mut png = Vec::new();
    image::RgbaImage::from_pixel(2, 2, image::Rgba([128, 128, 255, 255]))
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    let uri = format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&png)
    );
    let p = write_gltf(
        "nouv.gltf",
        &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        &[0, 1, 2],
        |j| {
            j["images"] = json!([{"uri": uri}]);
            j["textures"] = json!([{"source": 0}]);
            j["materials"] = json!([{"normalTexture": {"index": 0}}]);
            j["meshes"][0]["primitives"][0]["material"] = json!(0);
        },
    );
    let s = load_gltf(&p).unwrap();
    assert!(
        s.warnings
            .iter()
            .any(|w| w.message.contains("normal map ignored")
                && w.code == "NORMAL_MAP_WITHOUT_UVS"
                && w.pointer == "/meshes/0/primitives/0"),
        "{:?}",
        s.warnings
    );
    let prim = &s.meshes[0].primitives[0];
    assert!(s.materials[prim.material].normal_texture.is_none());
    render_clean(&s);
}

#[test]
fn a_scene_without_instances_renders_the_background() {
    let p = write_gltf(
        "empty.gltf",
        &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        &[0, 1, 2],
        |j| {
            j["scenes"] = json!([{"nodes": []}]);
        },
    );
    let s = load_gltf(&p).unwrap();
    assert!(s
        .warnings
        .iter()
        .any(|w| w.message.contains("no mesh instances") && w.code == "SCENE_EMPTY"));
    let (img, plan) = render_clean_with_plan(&s);
    // Nothing but the sky: each pixel the hemisphere seen along its direction (within a level
    // of the CPU's evaluation), darker below the horizon than above.
    let want = plan.background_image(img.width(), img.height());
    let worst = img
        .pixels()
        .zip(want.pixels())
        .flat_map(|(a, b)| (0..3).map(move |k| (a[k] as i32 - b[k] as i32).abs()))
        .max()
        .unwrap();
    assert!(worst <= 1, "the background differs by {worst} levels");
    let (top, bottom) = (img.get_pixel(32, 0), img.get_pixel(32, img.height() - 1));
    assert_ne!(top, bottom, "a gradient, not one colour");
}
