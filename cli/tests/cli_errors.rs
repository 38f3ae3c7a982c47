//! Bad input gets one clear error line and a non-zero exit, never a panic (the CLI binary is run).

use base64::Engine as _;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::Command;

fn tmp(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("cli-errors")
        .join(name);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A one-triangle glTF: positions (3 × vec3 f32) then u16 indices, in one buffer.
fn triangle_bytes(indices: [u16; 3]) -> Vec<u8> {
    let mut b = Vec::new();
    for v in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        for c in v {
            b.extend(c.to_le_bytes());
        }
    }
    for i in indices {
        b.extend(i.to_le_bytes());
    }
    b.extend([0, 0]); // pad to 4
    b
}

fn triangle_json(buffer: Value, position_count: usize) -> Value {
    json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [buffer],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": 36, "byteLength": 6}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": position_count, "type": "VEC3",
             "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0]},
            {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}
        ]
    })
}

fn data_uri(bytes: &[u8]) -> String {
    format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(bytes)
    )
}

fn glb(json: &Value, bin: &[u8]) -> Vec<u8> {
    let mut j = serde_json::to_vec(json).unwrap();
    while j.len() & 3 != 0 {
        j.push(b' ');
    }
    let total = 12 + 8 + j.len() + 8 + bin.len();
    let mut out = Vec::new();
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((j.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(&j);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    out
}

fn run(args: &[&str], dir: &Path) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_umbra"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).to_string(),
    )
}

fn assert_one_line_error(file: &Path, expect: &str) {
    let dir = file.parent().unwrap();
    let out_png = dir.join("out.png");
    let _ = std::fs::remove_file(&out_png);
    let (ok, stderr) = run(
        &[
            "render",
            file.to_str().unwrap(),
            "-o",
            out_png.to_str().unwrap(),
        ],
        dir,
    );
    assert!(!ok, "{}: should fail", file.display());
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(
        lines.len(),
        1,
        "{}: expected one error line, got:\n{stderr}",
        file.display()
    );
    assert!(lines[0].starts_with("error: "), "{stderr}");
    assert!(
        lines[0].to_lowercase().contains(expect),
        "{}: '{}' should mention '{expect}'",
        file.display(),
        lines[0]
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(!out_png.exists(), "no image may be written on error");
}

#[test]
fn missing_file() {
    let d = tmp("missing");
    assert_one_line_error(&d.join("nope.gltf"), "cannot read");
}

#[test]
fn empty_file() {
    let d = tmp("empty");
    let p = d.join("empty.gltf");
    std::fs::write(&p, b"").unwrap();
    assert_one_line_error(&p, "empty");
}

#[test]
fn invalid_json() {
    let d = tmp("json");
    let p = d.join("bad.gltf");
    std::fs::write(&p, b"{ \"asset\": { \"version\": \"2.0\" }, nope").unwrap();
    assert_one_line_error(&p, "not a valid gltf");
}

#[test]
fn truncated_glb() {
    let d = tmp("truncated");
    let bin = triangle_bytes([0, 1, 2]);
    let full = glb(&triangle_json(json!({"byteLength": bin.len()}), 3), &bin);
    let p = d.join("cut.glb");
    std::fs::write(&p, &full[..full.len() - 20]).unwrap();
    assert_one_line_error(&p, "not a valid gltf");
    // The untruncated file renders (so the failure above is the truncation's).
    let ok = d.join("whole.glb");
    std::fs::write(&ok, &full).unwrap();
    let (success, stderr) = run(
        &[
            "render",
            ok.to_str().unwrap(),
            "-o",
            d.join("whole.png").to_str().unwrap(),
            "--size",
            "32x32",
            "--validation",
        ],
        &d,
    );
    assert!(success, "{stderr}");
}

#[test]
fn buffer_uri_outside_the_model_folder() {
    let d = tmp("escape");
    let model = d.join("model");
    std::fs::create_dir_all(&model).unwrap();
    std::fs::write(d.join("secret.bin"), triangle_bytes([0, 1, 2])).unwrap();
    let p = model.join("escape.gltf");
    std::fs::write(
        &p,
        triangle_json(json!({"uri": "../secret.bin", "byteLength": 44}), 3).to_string(),
    )
    .unwrap();
    assert_one_line_error(&p, "outside the model's folder");
    let p = model.join("absolute.gltf");
    let abs = d.join("secret.bin").to_string_lossy().to_string();
    std::fs::write(
        &p,
        triangle_json(json!({"uri": abs, "byteLength": 44}), 3).to_string(),
    )
    .unwrap();
    assert_one_line_error(&p, "outside the model's folder");
}

#[test]
fn accessor_reading_past_its_buffer() {
    let d = tmp("accessor");
    let p = d.join("long.gltf");
    let bin = triangle_bytes([0, 1, 2]);
    std::fs::write(
        &p,
        triangle_json(json!({"uri": data_uri(&bin), "byteLength": bin.len()}), 300).to_string(),
    )
    .unwrap();
    assert_one_line_error(&p, "past the end");
}

#[test]
fn index_out_of_range() {
    let d = tmp("index");
    let p = d.join("index.gltf");
    let bin = triangle_bytes([0, 1, 99]);
    std::fs::write(
        &p,
        triangle_json(json!({"uri": data_uri(&bin), "byteLength": bin.len()}), 3).to_string(),
    )
    .unwrap();
    assert_one_line_error(&p, "out of range");
}

/// Image, texture and sampler objects that name nothing (an empty `images` entry panicked inside
/// gltf 1.4.1 before the pre-check): one error line each.
#[test]
fn images_and_textures_without_a_source() {
    let d = tmp("images");
    let bin = triangle_bytes([0, 1, 2]);
    let cases = [
        (
            "empty_image",
            json!([{}]),
            json!([{"source": 0}]),
            "exactly one source",
        ),
        (
            "both_sources",
            json!([{"uri": "a.png", "bufferView": 0, "mimeType": "image/png"}]),
            json!([{"source": 0}]),
            "exactly one source",
        ),
        (
            "view_without_mime",
            json!([{"bufferView": 0}]),
            json!([{"source": 0}]),
            "exactly one source",
        ),
        (
            "missing_image",
            json!([]),
            json!([{"source": 3}]),
            "texture 0 source",
        ),
        (
            "missing_sampler",
            json!([{"uri": "a.png"}]),
            json!([{"source": 0, "sampler": 2}]),
            "texture 0 sampler",
        ),
    ];
    for (name, images, textures, expect) in cases {
        let mut j = triangle_json(json!({"uri": data_uri(&bin), "byteLength": bin.len()}), 3);
        j["images"] = images;
        j["textures"] = textures;
        j["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
        j["meshes"][0]["primitives"][0]["material"] = json!(0);
        let p = d.join(format!("{name}.gltf"));
        std::fs::write(&p, j.to_string()).unwrap();
        assert_one_line_error(&p, expect);
    }
}

/// A sparse accessor without a buffer view and a huge count (found by 200,000-mutation fuzzing of
/// the generated corpus: reading it tried to allocate 1.2 TB and aborted the process).
#[test]
fn huge_accessor_without_a_buffer_view() {
    let d = tmp("viewless");
    let bin = triangle_bytes([0, 1, 2]);
    let mut j = triangle_json(json!({"uri": data_uri(&bin), "byteLength": bin.len()}), 3);
    j["accessors"][0] = json!({
        "componentType": 5126, "count": 99_999_999_999u64, "type": "VEC3",
        "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0],
        "sparse": {"count": 3, "indices": {"bufferView": 1, "componentType": 5123},
                   "values": {"bufferView": 0}}
    });
    let p = d.join("viewless.gltf");
    std::fs::write(&p, j.to_string()).unwrap();
    assert_one_line_error(&p, "no buffer view");
}

/// glTF 1.0 and files without `asset.version` are refused (they used to render an empty image
/// with exit 0).
#[test]
fn gltf_1_and_missing_version() {
    let d = tmp("version");
    let p = d.join("v1.gltf");
    std::fs::write(&p, br#"{"asset":{"version":"1.0"}}"#).unwrap();
    assert_one_line_error(&p, "gltf version 1.0 is not supported");
    let p = d.join("noversion.gltf");
    std::fs::write(&p, br#"{"asset":{}}"#).unwrap();
    assert_one_line_error(&p, "asset.version is missing");
    let bin = triangle_bytes([0, 1, 2]);
    let mut j = triangle_json(json!({"uri": data_uri(&bin), "byteLength": bin.len()}), 3);
    j["asset"] = json!({"version": "1.0"});
    let p = d.join("v1_with_mesh.gltf");
    std::fs::write(&p, j.to_string()).unwrap();
    assert_one_line_error(&p, "gltf version 1.0 is not supported");
}

#[test]
fn bad_arguments() {
    let d = tmp("args");
    let id = "[[1,0,0,0],[0,1,0,0],[0,0,1,5],[0,0,0,1]]";
    for (name, text) in [
        ("bad.json", "[[1,2"),
        (
            "short.json",
            &*format!("[{id}, [[1,0,0,0],[0,1,0,0],[0,0,1,5]]]"),
        ),
        ("same.json", r#"[{"eye": [1, 2, 3], "target": [1, 2, 3]}]"#),
        ("empty.json", "[]"),
        ("flat.json", "[[[1,0,0,0],[0,0,0,0],[0,0,1,5],[0,0,0,1]]]"),
        (
            "far.json",
            r#"[{"eye": [0, 0, 1e30], "target": [0, 0, 0]}]"#,
        ),
        ("one.json", &*format!("[{id}]")),
    ] {
        std::fs::write(d.join(name), text).unwrap();
    }
    std::fs::create_dir_all(d.join("broken")).unwrap();
    std::fs::write(d.join("broken/sweep.json"), "{\"rows\": [1").unwrap();
    for (args, expect) in [
        (vec!["render", "--size", "0x0"], "size"),
        (vec!["render", "--camera", "7"], "camera 7"),
        (vec!["render", "--eye", "1,2,3"], "--target"),
        (
            vec!["render", "--eye", "0,0,1e30", "--target", "0,0,0"],
            "--eye: its position is 1e30 from the origin",
        ),
        (vec!["render", "--sun-dir", "0,0,0"], "zero"),
        (vec!["render", "--shadow-map", "3"], "shadow-map"),
        (vec!["render", "--shadow-budget", "150%"], "below 100%"),
        (vec!["render", "--shadow-budget", "abc"], "not a fraction"),
        (vec!["sweep", "no-such-scene.gltf"], "no such file"),
        (vec!["render", "--time", "nan"], "finite"),
        (vec!["render", "--animation", "3"], "no animations"),
        (vec!["render", "--frames", "3", "-o", "x.png"], "pattern"),
        (vec!["render", "--frames", "3", "-o", "x%q.png"], "%0nd"),
        (vec!["render", "--frames", "2", "--fps", "0"], "frame rate"),
        (vec!["render", "--ssaa", "3"], "3 is not in 1..=2"),
        (
            vec!["render", "--views", "missing.json", "-o", "v%d.png"],
            "missing.json",
        ),
        (
            vec!["render", "--views", "bad.json", "-o", "v%d.png"],
            "not json",
        ),
        (
            vec!["render", "--views", "short.json", "-o", "v%d.png"],
            "pose 1: a matrix of 12",
        ),
        (
            vec!["render", "--views", "same.json", "-o", "v%d.png"],
            "same point",
        ),
        (
            vec!["render", "--views", "empty.json", "-o", "v%d.png"],
            "no poses",
        ),
        (
            vec!["render", "--views", "flat.json", "-o", "v%d.png"],
            "pose 0: not a camera pose: its axes are degenerate",
        ),
        (
            vec!["render", "--views", "far.json", "-o", "v%d.png"],
            "pose 0: \"eye\": its position is 1e30 from the origin, beyond 1e18",
        ),
        (
            vec!["render", "--views", "one.json", "-o", "v.png"],
            "pattern",
        ),
        (vec!["render", "--outputs", "depth"], "--views"),
        (
            vec!["report", "no-such-folder"],
            "no-such-folder: not a folder",
        ),
        (vec!["report", "broken"], "broken/sweep.json: eof"),
    ] {
        let (ok, stderr) = run(&args, &d);
        assert!(!ok, "{args:?} should fail");
        assert!(stderr.to_lowercase().contains(expect), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
}
