//! Helpers shared by the GPU tests: a validated context, projection of world points to pixels,
//! image statistics and artifact output.
#![allow(dead_code)]

pub mod animated;
pub mod corpus;
pub mod gltf_builder;
pub mod image_diff;

#[allow(unused_imports)]
pub use image_diff::{image_diff, ImageDiff};

use glam::{Mat4, Vec3, Vec4};
use std::path::PathBuf;
use std::sync::Arc;
use umbra::gpu::{Context, ContextDesc, Validation};
use umbra::math::projection::{ndc_to_pixel, pixel_to_ndc};

/// A validated context for one test. It derefs to `Arc<Context>`; when it goes out of scope it
/// drops the context (it must hold the last reference) and fails the test if any warning or error
/// arrived, destroy-time messages (leaked objects) included. While it lives, no other thread of
/// the test process holds one ([`one_at_a_time`]).
pub struct TestContext {
    ctx: Option<Arc<Context>>,
    log: Arc<umbra::ValidationLog>,
}

impl std::ops::Deref for TestContext {
    type Target = Arc<Context>;
    fn deref(&self) -> &Arc<Context> {
        self.ctx.as_ref().unwrap()
    }
}

impl Drop for TestContext {
    fn drop(&mut self) {
        // Declared first, dropped last: the turn passes on once the device is gone.
        let _turn = one_at_a_time::Release;
        let ctx = self.ctx.take().unwrap();
        if std::thread::panicking() {
            return;
        }
        assert_eq!(
            Arc::strong_count(&ctx),
            1,
            "something still holds the context at the end of the test"
        );
        drop(ctx);
        assert_eq!(
            self.log.problem_count(),
            0,
            "validation messages (counted after the context was destroyed): {:#?}",
            self.log.messages()
        );
    }
}

/// A context with the Khronos validation layer (synchronization validation on). Fails if the
/// layer is missing: GPU tests never run unvalidated.
pub fn context() -> TestContext {
    context_with(ContextDesc::default())
}

/// `context()` from `desc` (its validation made `Required`).
pub fn context_with(desc: ContextDesc) -> TestContext {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    crash_report::install();
    one_at_a_time::acquire();
    let ctx = Context::new(&ContextDesc {
        validation: Validation::Required,
        ..desc
    })
    .unwrap_or_else(|e| {
        one_at_a_time::release();
        panic!("cannot create a validated Vulkan context: {e}")
    });
    TestContext {
        log: ctx.validation_log.clone(),
        ctx: Some(ctx),
    }
}

/// `view` of `scene` rendered at `w`×`h` by a fresh renderer made with `options`.
pub fn render_with(
    ctx: &std::sync::Arc<Context>,
    scene: &umbra::scene::Scene,
    options: &umbra::plan::SceneOptions,
    view: &umbra::View,
    (w, h): (u32, u32),
) -> umbra::RenderedFrame {
    let mut r = umbra::Renderer::with_options(ctx, scene, options).unwrap();
    r.render(view, w, h).unwrap()
}

/// Fails the test if the validation layer reported any warning or error.
pub fn assert_validation_clean(ctx: &Context) {
    assert!(ctx.validation_enabled, "validation layer not enabled");
    let n = ctx.validation_log.problem_count();
    assert_eq!(
        n,
        0,
        "validation messages: {:#?}",
        ctx.validation_log.messages()
    );
}

/// Folder for test artifacts (images), under target/.
pub fn out_dir() -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("umbra-test-output");
    std::fs::create_dir_all(&d).ok();
    d
}

/// Saves an image artifact and returns its path.
pub fn save(img: &image::RgbaImage, name: &str) -> PathBuf {
    let p = out_dir().join(name);
    img.save(&p).expect("save artifact");
    p
}

/// Pixel (x right, y down) of a world point under `clip_from_world`, if in front of the camera.
pub fn project(clip_from_world: &Mat4, p: Vec3, w: u32, h: u32) -> Option<(f32, f32)> {
    let c = *clip_from_world * Vec4::new(p.x, p.y, p.z, 1.0);
    if c.w <= 0.0 {
        return None;
    }
    Some(ndc_to_pixel(c.truncate().truncate() / c.w, w, h))
}

/// The world-space ray through the centre of pixel (x, y).
pub fn pixel_ray(clip_from_world: &Mat4, x: u32, y: u32, w: u32, h: u32) -> (Vec3, Vec3) {
    let inv = clip_from_world.inverse();
    let n = pixel_to_ndc(x as f32 + 0.5, y as f32 + 0.5, w, h);
    // Reversed-z: depth 1 is the near plane, small depth is far away.
    let a = inv * Vec4::new(n.x, n.y, 1.0, 1.0);
    let b = inv * Vec4::new(n.x, n.y, 0.01, 1.0);
    let a = a.truncate() / a.w;
    let b = b.truncate() / b.w;
    (a, (b - a).normalize())
}

/// The point of the ground plane y = 0 seen at pixel (x, y) of a `w`×`h` frame planned by `plan`,
/// when the reference's first hit there (`distance`, from the eye) is that plane.
pub fn ground_point(
    plan: &umbra::plan::FramePlan,
    distance: &[f32],
    (x, y): (u32, u32),
    (w, h): (u32, u32),
) -> Option<Vec3> {
    let (_, d) = pixel_ray(&plan.clip_from_scene(), x, y, w, h);
    // Reference distances run from the eye.
    let o = plan.camera_position + plan.origin;
    if d.y >= 0.0 {
        return None;
    }
    let t = -o.y / d.y;
    let dist = distance[(y * w + x) as usize];
    ((dist - t).abs() < 1e-3 * t).then(|| o + d * t)
}

/// A scene named `name` holding a grey ground plane `size` across at y = 0, and nothing else.
pub fn ground_scene(size: f32, name: &str) -> umbra::scene::Scene {
    use umbra::scene::built::shapes::{add_object, colored, plane};
    let mut s = umbra::scene::Scene {
        name: name.into(),
        ..Default::default()
    };
    add_object(
        &mut s,
        "ground",
        plane(size, 1.0),
        colored(Vec3::splat(0.8), 1.0),
        Mat4::IDENTITY,
    );
    s
}

/// sRGB byte → linear.
pub fn srgb_to_linear(b: u8) -> f32 {
    let c = b as f32 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear → sRGB byte.
pub fn linear_to_srgb(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    255.0
        * if c <= 0.0031308 {
            c * 12.92
        } else {
            1.055 * c.powf(1.0 / 2.4) - 0.055
        }
}

/// One validated context at a time in a test process. The Khronos layer (1.3.239, Debian 12)
/// finds each instance's and device's state in a global map that it reads without a lock on every
/// call; creating or destroying a device on one thread while another thread's device is in use can
/// crash it (KhronosGroup/Vulkan-ValidationLayers#4391: two CI runs of this suite ended in a
/// SIGSEGV inside the layer, in tests/culling.rs and lab/tests/lights.rs). With one context alive
/// its two entries stay in the map's inline slots and the map never changes under a reader. A GPU
/// test waits for the one before it; tests without a context still run in parallel (the engine's
/// and the lab's GPU test binaries: 133–134 s this way, 131 s unserialised in the same minutes;
/// lavapipe's threads already fill both cores).
/// Re-entrant per thread, so a test may hold two contexts.
mod one_at_a_time {
    use std::cell::RefCell;
    use std::sync::{Mutex, MutexGuard, PoisonError};

    static TURN: Mutex<()> = Mutex::new(());

    thread_local! {
        /// This thread's contexts and, while there are any, its turn.
        static HELD: RefCell<(usize, Option<MutexGuard<'static, ()>>)> =
            const { RefCell::new((0, None)) };
    }

    /// Waits for this thread's turn unless it already has it.
    pub fn acquire() {
        HELD.with(|h| {
            let mut h = h.borrow_mut();
            if h.0 == 0 {
                // A test that failed while holding the turn poisons the lock; the turn is free.
                h.1 = Some(TURN.lock().unwrap_or_else(PoisonError::into_inner));
            }
            h.0 += 1;
        });
    }

    /// Gives the turn back with this thread's last context.
    pub fn release() {
        HELD.with(|h| {
            let mut h = h.borrow_mut();
            h.0 = h.0.saturating_sub(1);
            if h.0 == 0 {
                h.1 = None;
            }
        });
    }

    /// Releases when dropped: after the context, which is dropped before it.
    pub struct Release;

    impl Drop for Release {
        fn drop(&mut self) {
            release();
        }
    }
}

/// A crash of the test process (a fault in the driver, the validation layer or umbra) prints the
/// faulting thread and its backtrace to the real stderr, then the process dies of the signal as
/// before: without it a rare crash in CI leaves only "signal: 11". A stack overflow is left to
/// Rust's own handler, which names the thread and aborts. Installed once per test binary by the
/// first [`context_with`].
#[cfg(all(target_os = "linux", target_env = "gnu"))]
mod crash_report {
    use std::io::Write;
    use std::sync::OnceLock;

    const SIGNALS: [libc::c_int; 4] = [libc::SIGSEGV, libc::SIGBUS, libc::SIGILL, libc::SIGFPE];

    /// The handlers these replaced (Rust's stack-overflow check for SIGSEGV and SIGBUS).
    static PREVIOUS: OnceLock<Vec<(libc::c_int, libc::sigaction)>> = OnceLock::new();

    extern "C" fn on_crash(
        sig: libc::c_int,
        info: *mut libc::siginfo_t,
        context: *mut libc::c_void,
    ) {
        // Rust's handler first: on a guard-page hit it reports the overflow and aborts; on any
        // other fault it puts back the default action and returns.
        let previous = PREVIOUS
            .get()
            .and_then(|p| p.iter().find(|(s, _)| *s == sig));
        if let Some((_, old)) = previous {
            let handler = old.sa_sigaction;
            if handler != libc::SIG_DFL && handler != libc::SIG_IGN {
                unsafe {
                    if old.sa_flags & libc::SA_SIGINFO != 0 {
                        let f: extern "C" fn(libc::c_int, *mut libc::siginfo_t, *mut libc::c_void) =
                            std::mem::transmute(handler);
                        f(sig, info, context);
                    } else {
                        let f: extern "C" fn(libc::c_int) = std::mem::transmute(handler);
                        f(sig);
                    }
                }
            }
        }
        // Printing allocates: should the crash have come from inside malloc and the report
        // deadlock, SIGALRM still ends the process.
        unsafe { libc::alarm(30) };
        // Straight to file descriptor 2: the test harness captures `eprintln!` per test thread,
        // and that capture dies with the process.
        let name = std::thread::current().name().map(str::to_owned);
        let _ = writeln!(
            std::io::stderr(),
            "test process: signal {sig} in thread '{}'; its frames, then their symbols:",
            name.as_deref()
                .unwrap_or("<unnamed: a driver or layer thread>"),
        );
        // Library and offset of each frame (the driver's have no symbols here).
        let mut frames = [std::ptr::null_mut(); 48];
        unsafe {
            let n = libc::backtrace(frames.as_mut_ptr(), frames.len() as libc::c_int);
            libc::backtrace_symbols_fd(frames.as_ptr(), n, 2);
        }
        // Walked here, symbolised on a fresh thread: the alternate signal stack is too small
        // for reading debug information.
        let trace = std::backtrace::Backtrace::force_capture();
        let text = std::thread::spawn(move || trace.to_string())
            .join()
            .unwrap_or_default();
        let _ = writeln!(std::io::stderr(), "{text}");
        // SA_RESETHAND put back the default action: returning re-runs the faulting
        // instruction, and the process ends with the signal as it would have.
    }

    pub fn install() {
        PREVIOUS.get_or_init(|| unsafe {
            // glibc's first backtrace loads libgcc_s, too much for a signal stack: done here.
            let mut frame = [std::ptr::null_mut(); 1];
            libc::backtrace(frame.as_mut_ptr(), 1);
            SIGNALS
                .iter()
                .map(|&sig| {
                    let mut action: libc::sigaction = std::mem::zeroed();
                    action.sa_sigaction = on_crash
                        as extern "C" fn(libc::c_int, *mut libc::siginfo_t, *mut libc::c_void)
                        as usize;
                    // On the alternate stack where the thread has one (Rust's threads do), as
                    // Rust's handler needs for an overflow.
                    action.sa_flags = libc::SA_SIGINFO | libc::SA_RESETHAND | libc::SA_ONSTACK;
                    libc::sigemptyset(&mut action.sa_mask);
                    let mut old: libc::sigaction = std::mem::zeroed();
                    libc::sigaction(sig, &action, &mut old);
                    (sig, old)
                })
                .collect()
        });
    }
}
