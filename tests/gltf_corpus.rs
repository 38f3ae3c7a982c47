//! Every model in the corpus (UMBRA_GLTF_CORPUS, set by .ci/run) loads and renders on lavapipe
//! without a validation message; FlightHelmet shows its textures and casts a shadow on a plane.

mod common;

use common::*;
use std::path::PathBuf;
use umbra::render::{Renderer, View, ViewMode};
use umbra::scene::{load_gltf, shapes::add_ground};

fn corpus_models() -> Vec<PathBuf> {
    let dir = corpus();
    assert!(
        dir.is_dir(),
        "glTF corpus not found at {} (set UMBRA_GLTF_CORPUS)",
        dir.display()
    );
    let mut out = Vec::new();
    let mut stack = vec![dir];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "gltf" || x == "glb") {
                out.push(p);
            }
        }
    }
    out.sort();
    assert!(
        out.len() >= 10,
        "expected the whole corpus, found {}",
        out.len()
    );
    out
}

#[test]
fn every_corpus_model_loads_and_renders() {
    let ctx = context();
    for path in corpus_models() {
        let mut scene = load_gltf(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert!(
            scene.triangle_count() > 0,
            "{}: no triangles",
            path.display()
        );
        add_ground(&mut scene);
        let mut r = Renderer::new(&ctx, &scene).unwrap();
        let cam = scene.default_camera(4.0 / 3.0);
        let f = r
            .render(&View::new(cam), 160, 120)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        save(&f.image, &format!("corpus_{name}.png"));
        // The model (and its ground) cover the view: few pixels keep the clear colour.
        let clear = *f.image.get_pixel(0, 0);
        let covered = f.image.pixels().filter(|p| p.0 != clear.0).count();
        assert!(
            covered > (160 * 120) / 5,
            "{}: only {covered} pixels drawn",
            path.display()
        );
        let distinct: std::collections::HashSet<[u8; 4]> = f.image.pixels().map(|p| p.0).collect();
        assert!(
            distinct.len() >= 4,
            "{}: image looks blank ({} colours)",
            path.display(),
            distinct.len()
        );
        assert_validation_clean(&ctx);
    }
}

#[test]
fn flight_helmet_shows_textures_normal_maps_and_a_shadow() {
    let path = corpus().join("FlightHelmet/FlightHelmet.gltf");
    let mut scene = load_gltf(&path).unwrap();
    assert!(scene.triangle_count() > 90_000);
    assert!(
        scene.textures.len() >= 10,
        "textures: {}",
        scene.textures.len()
    );
    assert!(
        scene
            .materials
            .iter()
            .filter(|m| m.normal_texture.is_some())
            .count()
            >= 5
    );
    add_ground(&mut scene);
    let ctx = context();
    let mut r = Renderer::new(&ctx, &scene).unwrap();
    let mut view = View::new(scene.default_camera(4.0 / 3.0));
    view.sun_direction = Some(glam::Vec3::new(-0.5, -1.0, -0.3));
    let f = r.render(&view, 320, 240).unwrap();
    save(&f.image, "flight_helmet.png");
    // Textured: many distinct colours (a flat-shaded untextured render has a few hundred).
    let distinct: std::collections::HashSet<[u8; 3]> =
        f.image.pixels().map(|p| [p[0], p[1], p[2]]).collect();
    assert!(
        distinct.len() > 3000,
        "FlightHelmet looks untextured: {} colours",
        distinct.len()
    );
    // A shadow on the ground: the visibility view has blocked pixels.
    view.mode = ViewMode::Shadow;
    let s = r.render(&view, 320, 240).unwrap();
    save(&s.image, "flight_helmet_shadow.png");
    let blocked = s.image.pixels().filter(|p| p[0] < 64).count();
    assert!(
        blocked > 2000,
        "FlightHelmet should shadow the ground: {blocked} blocked pixels"
    );
    assert_validation_clean(&ctx);
}
