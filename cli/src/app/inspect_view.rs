//! `umbra inspect`'s text and Markdown views of the JSON report (`scene::inspect`).

use serde_json::Value;
use umbra_lab::table::Table;

/// A JSON value as a short cell: strings bare, null as "–", arrays joined, floats to 4 digits.
fn cell(v: &Value) -> String {
    match v {
        Value::Null => "–".into(),
        Value::String(s) => s.clone(),
        Value::Number(n) => match n.as_f64() {
            Some(f) if n.is_f64() => {
                if f != 0.0 && (f.abs() < 1e-3 || f.abs() >= 1e6) {
                    format!("{f:.3e}")
                } else {
                    format!("{:.4}", f)
                        .trim_end_matches('0')
                        .trim_end_matches('.')
                        .to_string()
                }
            }
            _ => n.to_string(),
        },
        Value::Bool(b) => if *b { "yes" } else { "no" }.into(),
        Value::Array(a) => a.iter().map(cell).collect::<Vec<_>>().join(", "),
        Value::Object(_) => v.to_string(),
    }
}

fn bytes(v: &Value) -> String {
    let b = v.as_f64().unwrap_or(0.0);
    if b >= 1024.0 * 1024.0 {
        format!("{:.1} MiB", b / (1024.0 * 1024.0))
    } else if b >= 1024.0 {
        format!("{:.1} KiB", b / 1024.0)
    } else {
        format!("{b} B")
    }
}

fn arr(v: &Value) -> &[Value] {
    v.as_array().map(Vec::as_slice).unwrap_or(&[])
}

/// The report as aligned text tables (`md` = false) or Markdown.
pub fn format_report(r: &Value, md: bool) -> String {
    let h = |t: &str| {
        if md {
            format!("\n### {t}\n\n")
        } else {
            format!("\n{t}\n")
        }
    };
    let mut out = String::new();
    out += &asset(r, md, &h);
    out += &totals(r, md, &h);
    out += &compression(&r["compression"], md, &h);
    out += &scale(r, md, &h);
    out += &exposure(r, &h);
    out += &shadow_plan(r, md, &h);
    out += &meshes(r, md, &h);
    out += &materials(r, md, &h);
    out += &textures(r, md, &h);
    out += &tree(r, md, &h);
    out += &motion(&r["motion"], md, &h);
    out += &findings(r, md, &h);
    out
}

/// The file and its asset block, with the extensions used.
fn asset(r: &Value, md: bool, h: &dyn Fn(&str) -> String) -> String {
    let mut out = String::new();
    out += &if md {
        format!("## {}\n", cell(&r["file"]["path"]))
    } else {
        format!("{}\n", cell(&r["file"]["path"]))
    };
    let mut t = Table::new(&["field", "value"]);
    t.row(vec![
        "file".into(),
        format!(
            "{} ({})",
            bytes(&r["file"]["bytes"]),
            cell(&r["file"]["container"])
        ),
    ]);
    for k in ["version", "generator", "copyright"] {
        t.row(vec![k.into(), cell(&r["asset"][k])]);
    }
    let ext = &r["extensions"];
    let sup = |e: &Value| {
        let n = cell(e);
        let ok = ext["supported"][&n].as_bool().unwrap_or(false);
        format!("{n}{}", if ok { "" } else { " (ignored)" })
    };
    t.row(vec![
        "extensions used".into(),
        arr(&ext["used"])
            .iter()
            .map(sup)
            .collect::<Vec<_>>()
            .join(", "),
    ]);
    t.row(vec!["extensions required".into(), cell(&ext["required"])]);
    out += &h("Asset");
    out += &t.render(md);
    out
}

/// What the loader decoded, per extension, and the quantized attributes (nothing for a plain file).
fn compression(c: &Value, md: bool, h: &dyn Fn(&str) -> String) -> String {
    let exts = c["extensions"].as_object();
    if exts.is_none_or(|e| e.is_empty()) {
        return String::new();
    }
    let mut t = Table::new(&["extension", "covers", "stored", "decoded", "decode ms"]);
    for (name, e) in exts.into_iter().flatten() {
        let covers = arr(&e["covers"]);
        let first = covers.first().map(cell).unwrap_or_default();
        t.row(vec![
            name.clone(),
            format!("{} ({first}…)", covers.len()),
            bytes(&e["bytes_stored"]),
            bytes(&e["bytes_decoded"]),
            cell(&e["decode_ms"]),
        ]);
    }
    let mut out = h("Compression");
    out += &t.render(md);
    let q = arr(&c["quantized_attributes"]);
    if !q.is_empty() {
        let mut t = Table::new(&["quantized accessor", "semantic", "stored as"]);
        for a in q {
            t.row(vec![
                cell(&a["accessor"]),
                cell(&a["semantic"]),
                cell(&a["stored"]),
            ]);
        }
        out += &t.render(md);
        let nodes = arr(&c["dequantizing_transforms"]);
        let list: Vec<String> = nodes.iter().map(|n| cell(&n["node"])).collect();
        out += &format!(
            "{}dequantized by the transforms of {} node(s): {}\n",
            if md { "\n" } else { "" },
            nodes.len(),
            list.join(", ")
        );
    }
    out
}

/// Triangles, vertices, draws and GPU bytes, in the file and as rendered.
fn totals(r: &Value, md: bool, h: &dyn Fn(&str) -> String) -> String {
    let mut out = String::new();
    let tot = &r["totals"];
    let mut t = Table::new(&["total", "value"]);
    for k in ["triangles", "vertices", "draw_calls"] {
        t.row(vec![
            format!("{} (rendered)", k.replace('_', " ")),
            format!("{} ({})", cell(&tot[k]), cell(&tot["rendered"][k])),
        ]);
    }
    for k in ["meshes", "materials", "textures", "images", "nodes"] {
        t.row(vec![k.into(), cell(&tot[k])]);
    }
    let g = &tot["gpu_bytes"];
    t.row(vec!["GPU geometry".into(), bytes(&g["geometry"])]);
    t.row(vec![
        "GPU textures (mip chains)".into(),
        bytes(&g["textures"]),
    ]);
    t.row(vec![
        "GPU shadow maps".into(),
        bytes(&r["shadow_plan"]["gpu_bytes"]),
    ]);
    out += &h("Totals");
    out += &t.render(md);
    out
}

/// The scene's size and depth precision.
fn scale(r: &Value, md: bool, h: &dyn Fn(&str) -> String) -> String {
    let mut out = String::new();
    let s = &r["scale"];
    if !s.is_null() {
        let mut t = Table::new(&["measure", "value"]);
        t.row(vec!["bounds min".into(), cell(&s["bounds"]["min"])]);
        t.row(vec!["bounds max".into(), cell(&s["bounds"]["max"])]);
        t.row(vec!["diagonal".into(), cell(&s["diagonal"])]);
        t.row(vec![
            "distance from origin".into(),
            cell(&s["distance_from_origin"]),
        ]);
        t.row(vec![
            "reversed-z Δd/d at the far corner".into(),
            cell(&s["reversed_z_relative_step_at_far_corner"]),
        ]);
        out += &h("Scale");
        out += &t.render(md);
    }
    out
}

/// The default view's metering and exposure.
fn exposure(r: &Value, h: &dyn Fn(&str) -> String) -> String {
    let mut out = String::new();
    let e = &r["exposure"];
    if !e.is_null() {
        out += &h("Exposure (default view)");
        out += &format!(
            "{}: metered {} lux, EV100 {}, scale {}, ambient sky {} ground {}, tone curve {}\n",
            cell(&e["mode"]),
            cell(&e["metered_lux"]),
            cell(&e["ev100"]),
            cell(&e["scale"]),
            cell(&e["ambient"][1]),
            cell(&e["ambient_ground"][1]),
            cell(&e["tonemap"])
        );
    }
    out
}

/// The default view's shadow plan: the light, the map and each view.
fn shadow_plan(r: &Value, md: bool, h: &dyn Fn(&str) -> String) -> String {
    let mut out = String::new();
    let p = &r["shadow_plan"];
    out += &h("Shadow plan (default view)");
    if p["light"].is_null() {
        out += &format!("{}\n", cell(&p["reason"]));
    } else {
        out += &format!(
            "light {} ({}), map {}² {}, {} view(s), {}\n",
            cell(&p["light"]),
            cell(&p["light_type"]),
            cell(&p["map_texels"]),
            cell(&p["format"]),
            cell(&p["cascades"]),
            bytes(&p["gpu_bytes"])
        );
        let mut t = Table::new(&[
            "view",
            "from depth",
            "to depth",
            "texel (world)",
            "draws inside",
        ]);
        for (i, v) in arr(&p["views"]).iter().enumerate() {
            t.row(vec![
                i.to_string(),
                cell(&v["from_depth"]),
                if v["to_depth"].is_null() {
                    "∞".into()
                } else {
                    cell(&v["to_depth"])
                },
                cell(&v["texel_world"]),
                cell(&v["draws_inside"]),
            ]);
        }
        out += &t.render(md);
    }
    out
}

/// One row per primitive.
fn meshes(r: &Value, md: bool, h: &dyn Fn(&str) -> String) -> String {
    let mut out = String::new();
    let mut t = Table::new(&[
        "mesh",
        "name",
        "inst",
        "prim",
        "mode",
        "verts",
        "indices",
        "tris",
        "material",
        "attributes",
    ]);
    for m in arr(&r["meshes"]) {
        for p in arr(&m["primitives"]) {
            t.row(vec![
                cell(&m["index"]),
                cell(&m["name"]),
                cell(&m["instances"]),
                cell(&p["index"]),
                cell(&p["mode"]),
                cell(&p["vertices"]),
                format!("{} {}", cell(&p["indices"]), cell(&p["index_type"])),
                cell(&p["triangles"]),
                cell(&p["material"]),
                cell(&p["attributes"]),
            ]);
        }
    }
    out += &h("Meshes");
    out += &t.render(md);
    out
}

/// One row per material, as Blinn-Phong.
fn materials(r: &Value, md: bool, h: &dyn Fn(&str) -> String) -> String {
    let mut out = String::new();
    let mut t = Table::new(&[
        "material",
        "name",
        "alpha",
        "double-sided",
        "textures",
        "tangents",
        "kd (factors)",
        "ks (factors)",
        "shininess",
    ]);
    for m in arr(&r["materials"]) {
        let tex: Vec<String> = arr(&m["textures"])
            .iter()
            .map(|x| {
                format!(
                    "{}:{}{}{}",
                    cell(&x["slot"]),
                    cell(&x["texture"]),
                    if x["tex_coord"].as_u64().unwrap_or(0) > 0 {
                        format!(" uv{}", cell(&x["tex_coord"]))
                    } else {
                        String::new()
                    },
                    if x["transform"].as_bool().unwrap_or(false) {
                        " (transform)"
                    } else {
                        ""
                    }
                )
            })
            .collect();
        let bp = &m["blinn_phong"];
        t.row(vec![
            cell(&m["index"]),
            cell(&m["name"]),
            format!(
                "{}{}",
                cell(&m["alpha_mode"]),
                if m["alpha_mode"] == "MASK" {
                    format!(" {}", cell(&m["alpha_cutoff"]))
                } else {
                    String::new()
                }
            ),
            cell(&m["double_sided"]),
            tex.join(" "),
            cell(&m["tangents"]),
            cell(&bp["kd"]),
            cell(&bp["ks"]),
            cell(&bp["shininess"]),
        ]);
    }
    out += &h("Materials (as Blinn-Phong)");
    out += &t.render(md);
    out
}

/// One row per texture.
fn textures(r: &Value, md: bool, h: &dyn Fn(&str) -> String) -> String {
    let mut out = String::new();
    let mut t = Table::new(&["texture", "image", "size", "colour space", "mips", "GPU"]);
    for x in arr(&r["textures"]) {
        t.row(vec![
            cell(&x["index"]),
            cell(&x["image"]),
            format!("{}×{}", cell(&x["width"]), cell(&x["height"])),
            cell(&x["color_space"]),
            cell(&x["mip_levels"]),
            bytes(&x["gpu_bytes"]),
        ]);
    }
    out += &h("Textures");
    out += &t.render(md);
    out
}

/// The node tree (the first 40 nodes), cameras and lights.
fn tree(r: &Value, md: bool, h: &dyn Fn(&str) -> String) -> String {
    let mut out = String::new();
    let st = &r["scene_tree"];
    let nodes = arr(&st["nodes"]);
    let mut t = Table::new(&[
        "node",
        "name",
        "in scene",
        "mesh",
        "camera",
        "light",
        "translation",
        "children",
    ]);
    for n in nodes.iter().take(40) {
        t.row(vec![
            cell(&n["index"]),
            cell(&n["name"]),
            cell(&n["in_scene"]),
            cell(&n["mesh"]),
            cell(&n["camera"]),
            cell(&n["light"]),
            cell(&n["translation"]),
            arr(&n["children"]).len().to_string(),
        ]);
    }
    out += &h("Nodes");
    out += &t.render(md);
    if nodes.len() > 40 {
        out += &format!("… {} more (all in --json)\n", nodes.len() - 40);
    }
    if !arr(&st["cameras"]).is_empty() || !arr(&st["lights"]).is_empty() {
        let mut t = Table::new(&["camera / light", "type", "values"]);
        for c in arr(&st["cameras"]) {
            t.row(vec![
                format!("camera {}", cell(&c["index"])),
                cell(&c["type"]),
                if c["type"] == "orthographic" {
                    format!(
                        "xmag {} ymag {} znear {} zfar {}",
                        cell(&c["xmag"]),
                        cell(&c["ymag"]),
                        cell(&c["znear"]),
                        cell(&c["zfar"])
                    )
                } else {
                    format!(
                        "yfov {} znear {} zfar {}",
                        cell(&c["yfov"]),
                        cell(&c["znear"]),
                        cell(&c["zfar"])
                    )
                },
            ]);
        }
        for l in arr(&st["lights"]) {
            t.row(vec![
                format!("light {}", cell(&l["index"])),
                cell(&l["type"]),
                format!(
                    "intensity {} {}, colour {}, range {}",
                    cell(&l["intensity"]),
                    cell(&l["intensity_unit"]),
                    cell(&l["color"]),
                    cell(&l["range"])
                ),
            ]);
        }
        out += &h("Cameras and lights");
        out += &t.render(md);
    }
    out
}

/// Every finding.
fn findings(r: &Value, md: bool, h: &dyn Fn(&str) -> String) -> String {
    let mut out = String::new();
    let f = arr(&r["findings"]);
    out += &h(&format!("Findings ({})", f.len()));
    if f.is_empty() {
        out += "none\n";
    } else {
        let mut t = Table::new(&["severity", "code", "pointer", "message"]);
        for x in f {
            t.row(vec![
                cell(&x["severity"]),
                cell(&x["code"]),
                cell(&x["pointer"]),
                cell(&x["message"]),
            ]);
        }
        out += &t.render(md);
    }
    out
}

/// The animations table (one row per animation, its channels tallied); nothing without one.
fn animations(anims: &[Value], md: bool, h: &dyn Fn(&str) -> String) -> String {
    let mut out = String::new();
    if !anims.is_empty() {
        let mut t = Table::new(&[
            "animation",
            "duration (s)",
            "channels",
            "interpolation",
            "keys",
            "nodes",
        ]);
        for a in anims {
            let ch = arr(&a["channels"]);
            // "20 rotation, 1 translation" and the interpolations used, in order of first use.
            let tally = |key: &str| {
                let mut seen: Vec<(String, usize)> = Vec::new();
                for c in ch {
                    let k = cell(&c[key]);
                    match seen.iter_mut().find(|(n, _)| *n == k) {
                        Some((_, n)) => *n += 1,
                        None => seen.push((k, 1)),
                    }
                }
                seen.iter()
                    .map(|(k, n)| format!("{n} {k}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            let keys = ch
                .iter()
                .filter_map(|c| c["keyframes"].as_u64())
                .max()
                .unwrap_or(0);
            t.row(vec![
                format!("{} '{}'", cell(&a["index"]), cell(&a["name"])),
                cell(&a["duration"]),
                tally("path"),
                tally("interpolation"),
                format!("up to {keys}"),
                arr(&a["target_nodes"]).len().to_string(),
            ]);
        }
        out += &h(&format!("Animations ({})", anims.len()));
        out += &t.render(md);
    }
    out
}

/// The motion tables: animations (one row per channel), skins and morph targets; nothing for
/// a file that does not move.
fn motion(m: &Value, md: bool, h: &dyn Fn(&str) -> String) -> String {
    let mut out = String::new();
    out += &animations(arr(&m["animations"]), md, h);
    let skins = arr(&m["skins"]);
    if !skins.is_empty() {
        let mut t = Table::new(&[
            "skin",
            "joints",
            "inverse bind matrices",
            "most influences",
            "nodes",
        ]);
        for s in skins {
            t.row(vec![
                format!("{} '{}'", cell(&s["index"]), cell(&s["name"])),
                cell(&s["joints"]),
                cell(&s["inverse_bind_matrices"]),
                cell(&s["max_influences"]),
                cell(&s["nodes"]),
            ]);
        }
        out += &h("Skins");
        out += &t.render(md);
    }
    let morphs = arr(&m["morph_targets"]);
    if !morphs.is_empty() {
        let mut t = Table::new(&[
            "mesh",
            "primitive",
            "targets",
            "attributes",
            "default weights",
        ]);
        for x in morphs {
            t.row(vec![
                cell(&x["mesh"]),
                cell(&x["primitive"]),
                cell(&x["targets"]),
                cell(&x["attributes"]),
                cell(&x["default_weights"]),
            ]);
        }
        out += &h("Morph targets");
        out += &t.render(md);
    }
    out
}
