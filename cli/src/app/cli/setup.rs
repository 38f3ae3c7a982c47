//! Turning arguments into a scene, its upload options and a view; the warnings and fallbacks
//! they print.

use super::*;
use anyhow::{anyhow, bail};
use std::path::PathBuf;
use umbra::plan::{ShadowFit, ShadowFormat, ShadowSettings, View};
use umbra::scene::anim::Playing;
use umbra::scene::{built::demo::demo_scene, gltf::load_gltf, Camera, Scene};

#[cfg(feature = "sweep")]
/// Loads a scene named on the command line: an existing file, `demo`, or a generated scene's
/// name (`scene::built::synthetic::by_name`). Prints its warnings; adds a ground plane to files when
/// `ground`.
pub fn load_named(spec: &str, ground: bool) -> anyhow::Result<Scene> {
    let path = std::path::Path::new(spec);
    let mut s = if path.exists() {
        load_gltf(path)?
    } else if spec == "demo" {
        demo_scene()
    } else if let Some(s) = umbra::scene::built::synthetic::by_name(spec) {
        s
    } else {
        bail!("{spec}: no such file, and not demo, town, town-mover, grazing, stability, double-sided, room, sun-and-spot, two-suns, lux-yard or spheres:N");
    };
    for w in &s.warnings {
        print_warning(&s.name, w);
    }
    if ground && path.exists() {
        umbra::scene::built::shapes::add_ground(&mut s);
    }
    Ok(s)
}

/// The file name of frame `i` of a sequence: `pattern` with its `%0Nd` or `%d` replaced by `i`
/// (zero-padded to N digits); an error names the pattern wanted when there is none.
pub fn frame_path(pattern: &std::path::Path, i: u32) -> anyhow::Result<PathBuf> {
    let text = pattern.to_string_lossy();
    let Some(start) = text.find('%') else {
        bail!("-o {text}: a sequence (--frames, --views) needs a frame-number pattern such as out_%04d.png");
    };
    let rest = &text[start + 1..];
    let digits: String = rest.chars().take_while(|c| c.is_ascii_digit()).collect();
    if !rest[digits.len()..].starts_with('d') {
        bail!("-o {text}: expected %d or %0Nd (such as %04d) after '%'");
    }
    let width: usize = digits.parse().unwrap_or(0).min(12);
    let end = start + 1 + digits.len() + 1;
    Ok(PathBuf::from(format!(
        "{}{i:0width$}{}",
        &text[..start],
        &text[end..]
    )))
}

/// What `--animation` and `--time` ask of `scene`: the animations and the time, or None for the
/// rest pose. A scene without animations at `--time` gets a warning and its rest pose.
pub fn playing(scene: &Scene, a: &ViewArgs) -> anyhow::Result<Option<(Playing, f32)>> {
    if a.time.is_none() && a.animation.is_none() {
        return Ok(None);
    }
    let rig = scene.rig.as_deref();
    let Some(spec) = a.animation.as_deref() else {
        if rig.is_none_or(|r| r.animations.is_empty()) {
            return Ok(None);
        }
        return Ok(Some((Playing::One(0), a.time.unwrap_or(0.0))));
    };
    let p = Playing::parse(spec, rig).map_err(|e| anyhow!(e))?;
    Ok(Some((p, a.time.unwrap_or(0.0))))
}

/// With `--shadow-budget`: chooses this view's shadow settings (`analysis::budget::choose`), sets
/// them on `view`, and prints the choice on one line.
#[cfg(feature = "sweep")]
pub fn apply_budget(
    scene: &Scene,
    view: &mut View,
    a: &ViewArgs,
    renderer: &mut umbra::Renderer,
) -> anyhow::Result<()> {
    use umbra_lab::analysis::{budget, chart::short_label_of};
    let Some(b) = a.shadow_budget else {
        return Ok(());
    };
    let reference = umbra_lab::reference::ReferenceScene::new(scene);
    let Some(c) = budget::choose(renderer, &reference, scene, view, a.size, b, None)? else {
        eprintln!("warning: --shadow-budget: no light casts a shadow; settings unchanged");
        return Ok(());
    };
    view.shadow = c.chosen.config.shadow;
    println!("{}", budget_line(&c, &short_label_of(&c.chosen.config)));
    Ok(())
}

/// The one-line report of a budget choice.
#[cfg(feature = "sweep")]
pub fn budget_line(c: &umbra_lab::analysis::budget::BudgetChoice, label: &str) -> String {
    let measured = c
        .measured
        .map(|m| format!(", measured {:.4} % at {} probes", m * 100.0, c.probes))
        .unwrap_or_default();
    let met = if c.met {
        ""
    } else {
        " — budget not reachable: the most accurate candidate tried"
    };
    format!(
        "shadow budget {:.3} %: {label} (predicted {:.4} %{measured}; {:.2}x the default's GPU time; {} render(s), {:.0} ms){met}",
        c.budget * 100.0,
        c.chosen.predicted * 100.0,
        c.chosen.relative_cost,
        c.verified.len(),
        c.ms
    )
}

#[cfg(not(feature = "sweep"))]
pub fn apply_budget(
    _: &Scene,
    _: &mut View,
    a: &ViewArgs,
    _: &mut umbra::Renderer,
) -> anyhow::Result<()> {
    if a.shadow_budget.is_some() {
        bail!("--shadow-budget needs umbra built with the `sweep` feature");
    }
    Ok(())
}

/// Prints one loader warning as `warning: NAME: MESSAGE [CODE POINTER]`: the finding code and
/// JSON pointer that `umbra inspect` reports for it.
pub fn print_warning(scene: &str, w: &umbra::scene::Warning) {
    let at = if w.pointer.is_empty() {
        String::new()
    } else {
        format!(" {}", w.pointer)
    };
    eprintln!("warning: {scene}: {} [{}{at}]", w.message, w.code);
}

/// Warns when `view` asked for exact shadows and the frame planned as `plan` could not have
/// them (it has several shadowed lights, or the device no fragment-shader stores).
pub fn warn_exact(view: &View, plan: &umbra::FramePlan) {
    if view.shadow.method.traces() && plan.shadows_on && !plan.exact_shadows() {
        eprintln!(
            "warning: --shadow-method exact: {} shadow view(s) (exact shadows need one shadowed \
             light, and a device with fragment-shader stores); shadow maps used",
            plan.shadow_views.len()
        );
    }
}

/// Loads SCENE or builds the demo, prints its warnings (`warning: NAME: …` on stderr, one per
/// line), and adds a ground plane when asked.
pub fn load_scene(path: Option<&PathBuf>, a: &ViewArgs) -> anyhow::Result<Scene> {
    let mut s = match (path, a.synthetic.as_deref()) {
        (Some(_), Some(_)) => bail!("give either SCENE or --synthetic, not both"),
        (Some(p), None) => load_gltf(p)?,
        (None, None) => demo_scene(),
        (None, Some(name)) => umbra::scene::built::synthetic::by_name(name).ok_or_else(|| {
            anyhow!(
                "--synthetic {name}: expected {} or spheres:N with N in 1..=256",
                umbra::scene::built::synthetic::NAMES.join(", ")
            )
        })?,
    };
    let ground = a.ground;
    for w in &s.warnings {
        print_warning(&s.name, w);
    }
    match playing(&s, a)? {
        Some((p, t)) => s.pose_at(&p, t),
        None if a.time.is_some() => {
            eprintln!(
                "warning: {}: --time: the scene has no animations; drawn at rest",
                s.name
            );
        }
        None => {}
    }
    if ground {
        umbra::scene::built::shapes::add_ground(&mut s);
    }
    Ok(s)
}

/// Upload options from arguments.
pub fn scene_options(a: &ViewArgs) -> umbra::plan::SceneOptions {
    umbra::plan::SceneOptions {
        anisotropy: a.anisotropy,
        culling: !a.no_culling,
        msaa: a.msaa,
        cpu_mips: None,
        deferred: a.deferred,
        receiver_split: a.receiver_split,
        shadow_cache: a.shadow_cache.unwrap_or(false),
        block_compressed: a.block_compressed,
    }
}

/// Upload options for runs of many frames (the viewer, image sequences): the shadow cache on
/// unless `--shadow-cache off`.
pub fn animated_scene_options(a: &ViewArgs) -> umbra::plan::SceneOptions {
    umbra::plan::SceneOptions {
        shadow_cache: a.shadow_cache.unwrap_or(true),
        ..scene_options(a)
    }
}

/// The documented fallback of `--msaa N` on a device without N samples: a warning line naming
/// the count used.
pub fn warn_msaa(a: &ViewArgs, samples: u32) {
    if let Some(n) = a.msaa.filter(|&n| n != samples) {
        eprintln!("warning: --msaa {n}: the device has no {n}-sample attachments; using {samples}");
    }
}

/// Builds the view from arguments.
pub fn make_view(scene: &Scene, a: &ViewArgs) -> anyhow::Result<View> {
    let aspect = a.size.0 as f32 / a.size.1 as f32;
    let camera = camera_of(scene, a, aspect)?;
    let mut v = View::new(camera);
    v.sun_direction = match a.sun_dir {
        Some(d) if d.length_squared() == 0.0 => bail!("--sun-dir must not be zero"),
        d => d,
    };
    v.sun_intensity = match a.sun_intensity {
        Some(i) if !(i.is_finite() && i >= 0.0) => {
            bail!("--sun-intensity must be a finite number >= 0")
        }
        i => i,
    };
    v.light_size = match a.light_size {
        Some(x) if !(x.is_finite() && (0.0..=1e6).contains(&x)) => {
            bail!("--light-size must be a number within 0..1e6")
        }
        x => x,
    };
    v.mode = a.mode;
    v.exposure = a.exposure;
    v.ambient = a.ambient;
    v.background = a.background;
    v.tonemap = a.tonemap;
    v.post_aa = a.post_aa.parse().unwrap_or_default();
    v.supersample = a.ssaa;
    if let Some(i) = a.shadow_light {
        let n = umbra::plan::effective_lights(&scene.lights, &v).len();
        if i >= n {
            bail!("--shadow-light {i}: the scene has {n} light(s) (0..{n})");
        }
    }
    v.shown_light = a.shadow_light;
    v.shadow = shadow_settings(a)?;
    Ok(v)
}

/// The camera the arguments ask for: `--eye`/`--target`, a glTF camera, or the scene's first
/// (its default framing without one).
fn camera_of(scene: &Scene, a: &ViewArgs, aspect: f32) -> anyhow::Result<Camera> {
    Ok(match (a.eye, a.target, a.camera) {
        (Some(eye), Some(target), _) => {
            if (target - eye).length_squared() == 0.0 {
                bail!("--eye and --target must differ");
            }
            let b = scene.bounds();
            let near = if b.is_empty() {
                0.01
            } else {
                (b.diagonal() * 1e-4).max(1e-4)
            };
            Camera::check_position(eye).map_err(|e| anyhow!("--eye: {e}"))?;
            Camera::check_position(target).map_err(|e| anyhow!("--target: {e}"))?;
            Camera::look_at(eye, target, 45f32.to_radians(), near)
        }
        (Some(_), None, _) | (None, Some(_), _) => bail!("--eye and --target go together"),
        (None, None, Some(i)) => *scene.cameras.get(i).ok_or_else(|| {
            anyhow!(
                "--camera {i}: the scene has {} camera(s)",
                scene.cameras.len()
            )
        })?,
        (None, None, None) => scene
            .cameras
            .first()
            .copied()
            .unwrap_or_else(|| scene.default_camera(aspect)),
    })
}

/// The shadow settings of the arguments (`--shadow-map` checked).
fn shadow_settings(a: &ViewArgs) -> anyhow::Result<ShadowSettings> {
    let sizes = ShadowSettings::MAP_SIZES;
    if !sizes.contains(&a.shadow_map) {
        bail!(
            "--shadow-map {} must be within {}..{}",
            a.shadow_map,
            sizes.start(),
            sizes.end()
        );
    }
    Ok(ShadowSettings {
        enabled: !a.no_shadows,
        method: a.shadow_method.parse().unwrap_or_default(),
        contact: a.contact_shadows,
        map_size: a.shadow_map,
        format: a.shadow_format.parse().unwrap_or(ShadowFormat::Auto),
        pcf: pcf_of(a.pcf),
        constant_bias: a.bias_constant,
        slope_bias: a.bias_slope,
        normal_offset: a.normal_offset,
        fit: match a.fit.as_str() {
            "scene" => ShadowFit::Scene,
            "sphere" => ShadowFit::Sphere,
            _ => ShadowFit::Camera,
        },
        snap: !a.no_snap,
        extent_steps: a.extent_steps,
        cascades: a.cascades,
        cube_face: a.cube_face,
        depth_fit: a.depth_fit,
        soft: true,
    })
}
