//! Soak: thousands of small offscreen frames with validation on; resident memory stops growing
//! after warm-up and no validation message arrives (counted after teardown).

mod common;

use common::*;
use umbra::{demo_scene, ContextDesc, Renderer, View, ViewMode};

/// Resident set size of this process in bytes (Linux /proc).
fn rss_bytes() -> u64 {
    let s = std::fs::read_to_string("/proc/self/statm").expect("/proc/self/statm");
    let pages: u64 = s.split_whitespace().nth(1).unwrap().parse().unwrap();
    pages * 4096
}

#[test]
fn ten_thousand_offscreen_frames_do_not_grow_memory() {
    let frames: usize = std::env::var("UMBRA_SOAK_FRAMES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(10_000);
    let warm_up = 500.min(frames / 4);
    // A leak check: the allocator is left as glibc sets it. With `keep_driver_heap` (the
    // default on lavapipe) glibc keeps up to 64 MiB of freed memory per arena resident by
    // design, and where fragments of it land moves RSS by a few MB (one CI run: 4.2 MB).
    let ctx = context_with(ContextDesc {
        keep_driver_heap: false,
        ..Default::default()
    });
    let scene = demo_scene();
    let mut r = Renderer::new(&ctx, &scene).unwrap();
    let mut view = View::new(scene.cameras[0]);
    let start = std::time::Instant::now();
    let (mut rss_warm, mut rss_mid) = (0, 0);
    let mid = warm_up + (frames - warm_up) / 2;
    for i in 0..frames {
        // Vary the work a little: both view modes, two sizes, shadows on and off.
        view.mode = if i % 2 == 0 {
            ViewMode::Lit
        } else {
            ViewMode::Shadow
        };
        view.shadow.enabled = i % 7 != 0;
        let (w, h) = if i % 3 == 0 { (64, 64) } else { (48, 32) };
        let f = r.render(&view, w, h).unwrap();
        assert_eq!(f.image.dimensions(), (w, h));
        if i + 1 == warm_up {
            rss_warm = rss_bytes();
        }
        if i + 1 == mid {
            rss_mid = rss_bytes();
        }
    }
    let rss_end = rss_bytes();
    let growth = rss_end as i64 - rss_warm as i64;
    let halves = (
        rss_mid as i64 - rss_warm as i64,
        rss_end as i64 - rss_mid as i64,
    );
    eprintln!(
        "{frames} frames in {:.1} s; RSS after {warm_up} frames {:.1} MB, at the end {:.1} MB, growth {:.2} MB ({:.2} + {:.2} MB by halves)",
        start.elapsed().as_secs_f64(),
        rss_warm as f64 / 1e6,
        rss_end as f64 / 1e6,
        growth as f64 / 1e6,
        halves.0 as f64 / 1e6,
        halves.1 as f64 / 1e6
    );
    // A leak grows both halves alike; where the allocator's fragments land moves RSS in steps of
    // about 1.05 MB, in one half (measured 0, 1.05, 1.05, 1.17, 2.11, 2.11 and, in one CI run,
    // 4.21 + 0.00 MB). Either half under 1 MB catches any leak of 210 bytes a frame or more (a
    // deliberate 256-byte leak a frame: 3.67 + 1.60 MB, it fails); the whole is bounded at
    // 8 MB, twice the largest step measured.
    assert!(
        halves.0.min(halves.1) < 1_000_000 && growth < 8_000_000,
        "resident memory grew by {:.2} + {:.2} MB over {} frames",
        halves.0 as f64 / 1e6,
        halves.1 as f64 / 1e6,
        frames - warm_up
    );
    drop(r);
}
