//! The CPU ray-cast reference: BVH against brute force, and shadow accuracy of the GPU frame
//! against exact visibility (lavapipe, validation on).

use crate::common::*;
use glam::Vec3;
use umbra::math::ray::Ray;
use umbra::plan::{View, ViewMode};
use umbra::render::Renderer;
use umbra::scene::{built::demo::demo_scene, gltf::load_gltf, Scene};
use umbra_lab::reference::{compare, ReferenceScene};

struct Rng(u64);
impl Rng {
    fn f(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// 10,000 random rays from around the scene towards points inside its bounds: the BVH's nearest
/// hit equals brute force over all triangles.
fn bvh_matches_brute_force(scene: &Scene) -> usize {
    let r = ReferenceScene::new(scene);
    let b = scene.bounds();
    let mut rng = Rng(0x2545_F491_4F6C_DD1D);
    let mut hits = 0;
    for _ in 0..10_000 {
        let pick = |rng: &mut Rng| b.min + (b.max - b.min) * Vec3::new(rng.f(), rng.f(), rng.f());
        let target = pick(&mut rng);
        let origin = b.center() + (pick(&mut rng) - b.center()) * 2.5;
        let ray = Ray::new(origin, (target - origin).normalize_or(Vec3::X));
        let a = r.bvh.intersect(&ray, 0.0, f32::INFINITY);
        let c = r.bvh.intersect_brute_force(&ray, 0.0, f32::INFINITY);
        assert_eq!(a.map(|h| h.t), c.map(|h| h.t), "ray {origin} -> {target}");
        hits += a.is_some() as usize;
    }
    hits
}

/// The BVH equals brute force on every generated corpus model, the demo, and FlightHelmet when the
/// extra corpus is present.
#[test]
fn bvh_equals_brute_force_on_corpus_and_demo() {
    let dir = out_dir().join("corpus_bvh");
    let mut scenes: Vec<Scene> = crate::common::corpus::write_corpus(&dir)
        .iter()
        .map(|p| load_gltf(p).unwrap())
        .collect();
    if let Some(extra) = crate::common::corpus::extra_corpus() {
        scenes.push(load_gltf(&extra.join("FlightHelmet/FlightHelmet.gltf")).unwrap());
    }
    scenes.push(demo_scene());
    for s in &scenes {
        let hits = bvh_matches_brute_force(s);
        // Rays aim at points inside the bounds: most hit (measured 2,5xx–7,xxx of 10,000).
        assert!(hits > 1000, "{}: rays should hit the model: {hits}", s.name);
    }
}

fn measure(map: u32) -> (umbra_lab::reference::Metrics, image::RgbaImage) {
    let ctx = context();
    let scene = demo_scene();
    let mut r = Renderer::new(&ctx, &scene).unwrap();
    r.set_read_depth(true);
    let mut view = View::new(scene.cameras[0]);
    view.shadow.map_size = map;
    let (w, h) = (1280, 720);
    let lit = r.render(&view, w, h).unwrap();
    view.mode = ViewMode::Shadow;
    let shadow = r.render(&view, w, h).unwrap();
    let reference = ReferenceScene::new(&scene).render(&lit.plan, w, h, lit.plan.ambient);
    let (m, diff) = compare(
        &lit.image,
        &shadow.image,
        lit.depth.as_ref().unwrap(),
        &lit.plan,
        &reference,
    );
    save(&diff, &format!("reference_diff_{map}.png"));
    assert_validation_clean(&ctx);
    (m, diff)
}

#[test]
fn demo_shadows_are_accurate_and_a_small_map_is_worse() {
    let (m2048, diff) = measure(2048);
    eprintln!("2048: {}", m2048.to_json());
    assert!(m2048.judged_pixels > 400_000, "{m2048:?}");
    assert!(
        m2048.misclassified < 0.01,
        "demo misclassification {:.4}% must be under 1%",
        m2048.misclassified * 100.0
    );
    assert!(
        m2048.psnr > 30.0 && m2048.flip < 0.05,
        "image error too large: {m2048:?}"
    );
    // The difference image marks exactly the misclassified pixels.
    let red = diff.pixels().filter(|p| p.0 == [255, 0, 0, 255]).count();
    let blue = diff.pixels().filter(|p| p.0 == [0, 80, 255, 255]).count();
    assert_eq!(
        red,
        (m2048.false_shadow * m2048.judged_pixels as f64).round() as usize
    );
    assert_eq!(
        blue,
        (m2048.false_light * m2048.judged_pixels as f64).round() as usize
    );
    let (m256, _) = measure(256);
    eprintln!("256: {}", m256.to_json());
    assert!(
        m256.misclassified > 3.0 * m2048.misclassified
            && m256.edge_misclassified > 2.0 * m2048.edge_misclassified,
        "a 256² map should be measurably worse: {:.5} vs {:.5}",
        m256.misclassified,
        m2048.misclassified
    );
}
