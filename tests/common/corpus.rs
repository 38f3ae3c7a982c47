//! The test suite's own glTF corpus, written by the project's code (never downloaded): every
//! container (external .bin and PNG files, .glb with embedded images, data URIs), u8/u16/u32 and
//! absent indices, triangle strips and fans, sparse accessors, a node hierarchy with non-uniform
//! and negative scale, normal-mapped materials with and without stored tangents, every texture
//! slot, samplers, KHR_lights_punctual (directional, spot, point), KHR_materials_unlit, an
//! alpha-masked and a double-sided material, two cameras, and the animated models of
//! `animated` (a skin, every interpolation, morph targets).

use super::gltf_builder::{png, Builder, Container, U16, U32, U8};
use glam::{Quat, Vec3};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use umbra::scene::built::shapes::{cuboid, quad, uv_sphere};
use umbra::scene::Primitive;

/// Writes every generated model into `dir` and returns their main files, sorted.
pub fn write_corpus(dir: &Path) -> Vec<PathBuf> {
    let mut out = vec![
        indexed_boxes(dir),
        strips_and_fans(dir),
        sparse_data_uri(dir),
        hierarchy_and_scale(dir),
        normal_mapped(dir),
        lights_cameras_materials(dir),
    ];
    out.extend(super::animated::write_animated(dir));
    out.sort();
    out
}

/// Every model file (.gltf / .glb) under `dir`, recursively, sorted.
pub fn models_under(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "gltf" || x == "glb") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// The extra real-world models of `UMBRA_GLTF_CORPUS`, if set (CI sets it).
pub fn extra_corpus() -> Option<PathBuf> {
    std::env::var_os("UMBRA_GLTF_CORPUS")
        .map(PathBuf::from)
        .filter(|p| !p.as_os_str().is_empty())
}

fn flat(v: &[Vec3]) -> Vec<f32> {
    v.iter().flat_map(|p| p.to_array()).collect()
}

fn flat2(v: &[glam::Vec2]) -> Vec<f32> {
    v.iter().flat_map(|p| p.to_array()).collect()
}

/// Position, normal and UV accessors of `p` (and TANGENT when `tangents`), as an attributes map.
fn attributes(b: &mut Builder, p: &Primitive, tangents: bool) -> Value {
    let pos = b.floats(&flat(&p.positions), 3, "VEC3");
    let nrm = b.floats(&flat(&p.normals), 3, "VEC3");
    let uv = b.floats(&flat2(&p.uvs), 2, "VEC2");
    let mut a = json!({"POSITION": pos, "NORMAL": nrm, "TEXCOORD_0": uv});
    if tangents {
        let t: Vec<f32> = p.tangents.iter().flat_map(|t| t.to_array()).collect();
        a["TANGENT"] = json!(b.floats(&t, 4, "VEC4"));
    }
    a
}

/// A checkerboard of `cells`×`cells` cells in two colours.
fn checker(size: u32, cells: u32, a: [u8; 4], c: [u8; 4]) -> image::RgbaImage {
    image::RgbaImage::from_fn(size, size, |x, y| {
        let odd = ((x * cells / size) + (y * cells / size)) % 2 == 1;
        image::Rgba(if odd { a } else { c })
    })
}

/// A tangent-space normal map of round bumps (+Y up the image).
fn bumps(size: u32) -> image::RgbaImage {
    image::RgbaImage::from_fn(size, size, |x, y| {
        let f = std::f32::consts::TAU * 4.0 / size as f32;
        let (dx, dy) = (
            0.6 * (x as f32 * f).cos(),
            -0.6 * (y as f32 * f).cos(), // image y runs down; +Y of the map runs up
        );
        let n = Vec3::new(-dx, -dy, 1.0).normalize();
        let e = |c: f32| ((c * 0.5 + 0.5) * 255.0).round() as u8;
        image::Rgba([e(n.x), e(n.y), e(n.z), 255])
    })
}

fn translation(x: f32, y: f32, z: f32) -> Value {
    json!({"translation": [x, y, z]})
}

/// Four boxes: u8, u16 and u32 indices and no indices, with a checker base-colour texture in an
/// external PNG and the geometry in an external .bin.
fn indexed_boxes(dir: &Path) -> PathBuf {
    let mut b = Builder::default();
    let img = b.image(png(&checker(
        64,
        8,
        [230, 120, 40, 255],
        [240, 240, 230, 255],
    )));
    let smp = b.sampler(9729, 9987, 10497, 33648);
    let tex = b.texture(img, Some(smp));
    let mat = b.material(json!({"name": "checker", "pbrMetallicRoughness": {
        "baseColorTexture": {"index": tex}, "metallicFactor": 0.0, "roughnessFactor": 0.6}}));
    let p = cuboid(Vec3::splat(0.6));
    for (i, ctype) in [Some(U8), Some(U16), Some(U32), None]
        .into_iter()
        .enumerate()
    {
        let prim = match ctype {
            Some(t) => {
                let attrs = attributes(&mut b, &p, false);
                let idx = b.indices(&p.indices, t);
                json!({"attributes": attrs, "indices": idx, "material": mat})
            }
            None => {
                // Non-indexed: the vertices of each triangle in order.
                let expand = |v: &[Vec3]| -> Vec<Vec3> {
                    p.indices.iter().map(|&i| v[i as usize]).collect()
                };
                let uvs: Vec<glam::Vec2> = p.indices.iter().map(|&i| p.uvs[i as usize]).collect();
                let pos = b.floats(&flat(&expand(&p.positions)), 3, "VEC3");
                let nrm = b.floats(&flat(&expand(&p.normals)), 3, "VEC3");
                let uv = b.floats(&flat2(&uvs), 2, "VEC2");
                json!({"attributes": {"POSITION": pos, "NORMAL": nrm, "TEXCOORD_0": uv}, "material": mat})
            }
        };
        let mesh = b.mesh(&format!("box{i}"), vec![prim]);
        let mut n = translation(-3.0 + 2.0 * i as f32, 0.6, 0.0);
        n["mesh"] = json!(mesh);
        b.node(n, true);
    }
    b.write(dir, "indexed_boxes", Container::External)
}

/// A zig-zag wall as a triangle strip (mode 5) and a pyramid as a triangle fan (mode 6, no
/// normals: the loader computes them), in a .glb with an embedded texture.
fn strips_and_fans(dir: &Path) -> PathBuf {
    let mut b = Builder::default();
    let img = b.image(png(&checker(
        32,
        4,
        [60, 140, 220, 255],
        [250, 250, 250, 255],
    )));
    let tex = b.texture(img, None);
    let mat = b.material(json!({"name": "strip", "doubleSided": true,
        "pbrMetallicRoughness": {"baseColorTexture": {"index": tex}, "metallicFactor": 0.0}}));
    // Strip: bottom/top pairs along x, zig-zagging in z.
    let (mut pos, mut nrm, mut uv) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..9 {
        let x = -2.0 + 0.5 * i as f32;
        let z = if i % 2 == 0 { 0.0 } else { 0.4 };
        for y in [0.0, 2.0] {
            pos.push(Vec3::new(x, y, z));
            nrm.push(Vec3::Z);
            uv.push(glam::Vec2::new(i as f32 / 8.0, 1.0 - y / 2.0));
        }
    }
    let (pa, na, ua) = (
        b.floats(&flat(&pos), 3, "VEC3"),
        b.floats(&flat(&nrm), 3, "VEC3"),
        b.floats(&flat2(&uv), 2, "VEC2"),
    );
    let strip = json!({"attributes": {"POSITION": pa, "NORMAL": na, "TEXCOORD_0": ua}, "mode": 5, "material": mat});
    // Fan: apex, then a ring of 6 around it (counter-clockwise seen from above).
    let mut fan = vec![Vec3::new(0.0, 1.5, 0.0)];
    for k in 0..=6 {
        let a = -(k as f32) * std::f32::consts::TAU / 6.0;
        fan.push(Vec3::new(a.cos(), 0.0, a.sin()));
    }
    let fa = b.floats(&flat(&fan), 3, "VEC3");
    let fi = b.indices(&(0..fan.len() as u32).collect::<Vec<_>>(), U16);
    let plain = b.material(
        json!({"name": "fan", "pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.7, 0.3, 1.0]}}),
    );
    let fan = json!({"attributes": {"POSITION": fa}, "indices": fi, "mode": 6, "material": plain});
    let m1 = b.mesh("strip", vec![strip]);
    let m2 = b.mesh("fan", vec![fan]);
    let mut n = translation(0.0, 0.0, -1.0);
    n["mesh"] = json!(m1);
    b.node(n, true);
    let mut n = translation(0.0, 0.0, 1.5);
    n["mesh"] = json!(m2);
    b.node(n, true);
    b.write(dir, "strips_and_fans", Container::Glb)
}

/// A box whose top is raised by a sparse accessor over a dense one, and a card whose positions
/// come from a sparse accessor without a buffer view, in a .gltf with data-URI buffer and image.
fn sparse_data_uri(dir: &Path) -> PathBuf {
    let mut b = Builder::default();
    let p = cuboid(Vec3::splat(0.5));
    let base = flat(&p.positions);
    let raised: Vec<(u16, [f32; 3])> = p
        .positions
        .iter()
        .enumerate()
        .filter(|(_, v)| v.y > 0.0)
        .map(|(i, v)| (i as u16, [v.x, v.y + 1.0, v.z]))
        .collect();
    let pos = b.sparse_vec3(p.positions.len(), Some(&base), &raised);
    let nrm = b.floats(&flat(&p.normals), 3, "VEC3");
    let idx = b.indices(&p.indices, U16);
    let img = b.image(png(&checker(
        16,
        2,
        [200, 40, 40, 255],
        [255, 255, 255, 255],
    )));
    let tex = b.texture(img, None);
    let uv = b.floats(&flat2(&p.uvs), 2, "VEC2");
    let mat = b.material(json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": tex}}}));
    let tower = json!({"attributes": {"POSITION": pos, "NORMAL": nrm, "TEXCOORD_0": uv}, "indices": idx, "material": mat});
    let card_pos = b.sparse_vec3(
        4,
        None,
        &[
            (0, [-0.8, 0.0, 0.0]),
            (1, [0.8, 0.0, 0.0]),
            (2, [0.8, 1.6, 0.0]),
            (3, [-0.8, 1.6, 0.0]),
        ],
    );
    let card_idx = b.indices(&[0, 1, 2, 0, 2, 3], U8);
    let two = b.material(json!({"doubleSided": true, "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.8, 0.2, 1.0]}}));
    let card = json!({"attributes": {"POSITION": card_pos}, "indices": card_idx, "material": two});
    let m1 = b.mesh("tower", vec![tower]);
    let m2 = b.mesh("card", vec![card]);
    let mut n = translation(-1.0, 0.5, 0.0);
    n["mesh"] = json!(m1);
    b.node(n, true);
    let mut n = translation(1.2, 0.0, 0.0);
    n["mesh"] = json!(m2);
    b.node(n, true);
    b.write(dir, "sparse_data_uri", Container::DataUri)
}

/// A rotated root with a non-uniformly scaled child, a mirrored child (negative scale) and a
/// grandchild given as a matrix; single-sided materials, so a mirrored winding must be handled.
fn hierarchy_and_scale(dir: &Path) -> PathBuf {
    let mut b = Builder::default();
    let p = cuboid(Vec3::splat(0.5));
    let attrs = attributes(&mut b, &p, false);
    let idx = b.indices(&p.indices, U16);
    let red =
        b.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.2, 0.2, 1.0]}}));
    let blue =
        b.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.3, 0.9, 1.0]}}));
    let box_red = b.mesh(
        "box_red",
        vec![json!({"attributes": attrs, "indices": idx, "material": red})],
    );
    let box_blue = b.mesh(
        "box_blue",
        vec![json!({"attributes": attrs, "indices": idx, "material": blue})],
    );
    let grandchild = b.node(
        json!({"mesh": box_blue, "matrix": [0.5, 0.0, 0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 1.0, 0.0, 1.0]}),
        false,
    );
    let stretched = b.node(
        json!({"mesh": box_red, "translation": [-1.5, 1.0, 0.0], "scale": [1.0, 2.0, 0.5]}),
        false,
    );
    let mirrored = b.node(
        json!({"mesh": box_red, "translation": [1.5, 0.5, 0.0], "scale": [-1.0, 1.0, 1.0], "children": [grandchild]}),
        false,
    );
    let q = Quat::from_rotation_y(30f32.to_radians());
    b.node(
        json!({"name": "root", "rotation": q.to_array(), "children": [stretched, mirrored]}),
        true,
    );
    b.write(dir, "hierarchy_and_scale", Container::External)
}

/// A box with stored tangents and a sphere without (MikkTSpace), sharing a material with every
/// texture slot (base colour, metallic-roughness, normal, occlusion, emissive), in a .glb.
fn normal_mapped(dir: &Path) -> PathBuf {
    let mut b = Builder::default();
    // Texture transforms that keep the clamped coordinates inside [0, 1].
    b.use_extension("KHR_texture_transform");
    let smp = b.sampler(9729, 9986, 33071, 33071);
    let base = b.image(png(&checker(
        64,
        4,
        [180, 180, 190, 255],
        [120, 90, 70, 255],
    )));
    let normal = b.image(png(&bumps(64)));
    let mr = b.image(png(&image::RgbaImage::from_fn(32, 32, |x, _| {
        image::Rgba([0, (x * 8) as u8, 255 - (x * 8) as u8, 255])
    })));
    let occ = b.image(png(&image::RgbaImage::from_pixel(
        8,
        8,
        image::Rgba([200, 0, 0, 255]),
    )));
    let emi = b.image(png(&checker(8, 2, [40, 10, 0, 255], [0, 0, 0, 255])));
    let t: Vec<usize> = [base, normal, mr, occ, emi]
        .iter()
        .map(|&i| b.texture(i, Some(smp)))
        .collect();
    let mat = b.material(json!({
        "name": "every_slot",
        "pbrMetallicRoughness": {"baseColorTexture": {"index": t[0], "extensions": {"KHR_texture_transform":
                                     {"offset": [0.25, 0.25], "rotation": 0.3, "scale": [0.5, 0.5]}}},
                                 "metallicRoughnessTexture": {"index": t[2]},
                                 "metallicFactor": 0.5, "roughnessFactor": 0.8},
        "normalTexture": {"index": t[1], "scale": 1.0, "extensions": {"KHR_texture_transform": {"offset": [0.25, 0.25], "scale": [0.5, 0.5]}}},
        "occlusionTexture": {"index": t[3], "strength": 0.8},
        "emissiveTexture": {"index": t[4]}, "emissiveFactor": [1.0, 1.0, 1.0]
    }));
    let bx = cuboid(Vec3::splat(0.7));
    let attrs = attributes(&mut b, &bx, true);
    let idx = b.indices(&bx.indices, U16);
    let m1 = b.mesh(
        "box_tangents",
        vec![json!({"attributes": attrs, "indices": idx, "material": mat})],
    );
    let sp = uv_sphere(0.8, 24, 12);
    let attrs = attributes(&mut b, &sp, false);
    let idx = b.indices(&sp.indices, U32);
    let m2 = b.mesh(
        "sphere_mikktspace",
        vec![json!({"attributes": attrs, "indices": idx, "material": mat})],
    );
    let mut n = translation(-1.2, 0.7, 0.0);
    n["mesh"] = json!(m1);
    b.node(n, true);
    let mut n = translation(1.2, 0.8, 0.0);
    n["mesh"] = json!(m2);
    b.node(n, true);
    b.write(dir, "normal_mapped", Container::Glb)
}

/// Directional, spot and point lights (KHR_lights_punctual), an unlit box (KHR_materials_unlit),
/// an alpha-masked card (stripes), a double-sided open card and two cameras.
fn lights_cameras_materials(dir: &Path) -> PathBuf {
    let mut b = Builder::default();
    b.use_extension("KHR_materials_unlit");
    let stripes = b.image(png(&image::RgbaImage::from_fn(32, 32, |x, _| {
        image::Rgba([90, 160, 60, if (x / 4) % 2 == 0 { 255 } else { 0 }])
    })));
    let stex = b.texture(stripes, None);
    let unlit = b.material(
        json!({"name": "unlit", "extensions": {"KHR_materials_unlit": {}},
        "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.5, 0.1, 1.0]}}),
    );
    let mask = b.material(
        json!({"name": "mask", "alphaMode": "MASK", "alphaCutoff": 0.5, "doubleSided": true,
        "pbrMetallicRoughness": {"baseColorTexture": {"index": stex}}}),
    );
    let two = b.material(json!({"name": "double_sided", "doubleSided": true,
        "pbrMetallicRoughness": {"baseColorFactor": [0.3, 0.5, 0.9, 1.0], "metallicFactor": 0.0}}));
    let bx = cuboid(Vec3::splat(0.5));
    let attrs = attributes(&mut b, &bx, false);
    let idx = b.indices(&bx.indices, U16);
    let m_box = b.mesh(
        "unlit_box",
        vec![json!({"attributes": attrs, "indices": idx, "material": unlit})],
    );
    let q = quad(1.6, 1.6);
    let attrs = attributes(&mut b, &q, false);
    let idx = b.indices(&q.indices, U8);
    let m_mask = b.mesh(
        "mask_card",
        vec![json!({"attributes": attrs, "indices": idx, "material": mask})],
    );
    let m_two = b.mesh(
        "open_card",
        vec![json!({"attributes": attrs, "indices": idx, "material": two})],
    );
    for (mesh, t) in [
        (m_box, [-1.5, 0.5, 0.0]),
        (m_mask, [0.0, 0.8, 0.0]),
        (m_two, [1.5, 0.8, 0.3]),
    ] {
        b.node(json!({"mesh": mesh, "translation": t}), true);
    }
    let sun = b.light(json!({"type": "directional", "intensity": 1.5, "color": [1.0, 0.97, 0.9]}));
    let spot = b.light(json!({"type": "spot", "intensity": 4.0, "range": 20.0,
        "spot": {"innerConeAngle": 0.3, "outerConeAngle": 0.6}}));
    let point = b.light(json!({"type": "point", "intensity": 2.0, "color": [0.6, 0.7, 1.0]}));
    let sun_dir = Vec3::new(-0.4, -1.0, -0.5).normalize();
    let q_sun = Quat::from_rotation_arc(Vec3::NEG_Z, sun_dir);
    let light_ext = |l: usize| json!({"KHR_lights_punctual": {"light": l}});
    b.node(
        json!({"rotation": q_sun.to_array(), "extensions": light_ext(sun)}),
        true,
    );
    let q_down = Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2);
    b.node(json!({"translation": [0.0, 4.0, 1.0], "rotation": q_down.to_array(), "extensions": light_ext(spot)}), true);
    b.node(
        json!({"translation": [2.0, 2.0, 2.0], "extensions": light_ext(point)}),
        true,
    );
    for (eye, zfar) in [
        (Vec3::new(0.0, 2.5, 6.0), Some(50.0)),
        (Vec3::new(5.0, 3.0, 3.0), None),
    ] {
        let cam = b.camera(0.8, 0.1, zfar);
        let look = glam::Mat4::look_at_rh(eye, Vec3::new(0.0, 0.5, 0.0), Vec3::Y).inverse();
        let (_, r, t) = look.to_scale_rotation_translation();
        b.node(
            json!({"camera": cam, "rotation": r.to_array(), "translation": t.to_array()}),
            true,
        );
    }
    b.write(dir, "lights_cameras_materials", Container::External)
}
