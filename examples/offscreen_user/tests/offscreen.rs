//! umbra as a dev-dependency with `default-features = false`: load a scene, render offscreen on
//! lavapipe with validation, read pixels, assert that validation stayed silent through teardown.

use umbra::{demo_scene, Context, ContextDesc, Renderer, Validation, View, ViewMode};

#[test]
fn render_read_pixels_and_check_validation() {
    let scene = demo_scene();
    let ctx = Context::new(&ContextDesc {
        validation: Validation::Required,
        ..Default::default()
    })
    .expect("Vulkan with the Khronos validation layer");
    let log = ctx.validation_log.clone();
    let mut renderer = Renderer::new(&ctx, &scene).unwrap();
    let mut view = View::new(scene.cameras[0]);
    let lit = renderer.render(&view, 160, 90).unwrap();
    view.mode = ViewMode::Shadow;
    let vis = renderer.render(&view, 160, 90).unwrap();
    assert_eq!(lit.image.dimensions(), (160, 90));
    // The demo's low sun: some visible ground is in shadow, most is lit.
    let blocked = vis.image.pixels().filter(|p| p[0] < 128).count();
    let lit_px = vis.image.pixels().filter(|p| p[0] >= 128).count();
    assert!(blocked > 300 && lit_px > 5000, "blocked {blocked}, lit {lit_px}");
    assert!(lit.plan.shadows_on && lit.stats.casters_drawn > 0);
    drop(renderer);
    drop(ctx);
    assert_eq!(log.problem_count(), 0, "{:?}", log.messages());
}
