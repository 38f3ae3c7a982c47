//! What a renderer costs to make on lavapipe or a GPU: the first one on a context, then more on
//! the same context, which find their pipelines made and warm (`gpu::pipeline_store`).
//!
//! `cargo run --release --example renderer_setup` (`UMBRA_DEVICE=llvmpipe` for lavapipe).

use std::time::Instant;

fn main() -> Result<(), umbra::GpuError> {
    let ctx = umbra::Context::new(&Default::default())?;
    let scene = umbra::demo_scene();
    let view = umbra::View::new(scene.default_camera(1.0));
    let ms = |t: Instant| t.elapsed().as_secs_f64() * 1e3;
    println!("{} at 256x256, one context:", ctx.device_name);
    for i in 0..6 {
        let start = Instant::now();
        let mut r = umbra::Renderer::new(&ctx, &scene)?;
        let made = ms(start);
        let t = Instant::now();
        r.render(&view, 256, 256)?;
        let first = ms(t);
        let t = Instant::now();
        r.render(&view, 256, 256)?;
        let second = ms(t);
        println!(
            "renderer {i}: made in {made:.1} ms, first frame {first:.1} ms, second {second:.1} ms \
             ({} pipelines stored)",
            ctx.stored_pipelines()
        );
    }
    Ok(())
}
