//! The viewer's on-screen panel (egui): frame figures, every setting that has a key as a widget,
//! the pick result, the scene tree and a key legend. Building it reads a [`PanelModel`] and
//! returns [`Command`]s; the viewer applies them exactly as it applies the keys. Every widget a
//! script may click (`ui:NAME`) records its rectangle under a stable name in [`Widgets`].

use super::actions::{Action, SunAngles, VIEW_CYCLE};
use super::scene_tree::SceneTree;
use std::collections::HashMap;
use umbra::plan::{Pcf, ShadowMethod, Tonemap, View, MAX_CASCADES};
use umbra::render::FrameSummary;

/// Frame figures, averaged over the last quarter second.
#[derive(Clone, Debug, Default)]
pub struct Stats {
    /// Frames per second.
    pub fps: f64,
    /// CPU milliseconds per frame (posing, planning, recording, submitting).
    pub cpu_ms: f64,
    /// GPU milliseconds of the shadow and camera passes.
    pub gpu_ms: Option<(f64, f64)>,
    /// Triangles in the scene.
    pub triangles: usize,
    /// The last frame's draws and shadow views.
    pub summary: FrameSummary,
}

/// What the panel shows and edits.
pub struct PanelModel<'a> {
    /// The scene's name.
    pub scene: &'a str,
    /// The view (settings are read from it; changes come back as commands).
    pub view: &'a View,
    /// The sun's angles.
    pub sun: SunAngles,
    /// Frame figures.
    pub stats: &'a Stats,
    /// Lights of the frame.
    pub lights: usize,
    /// The scene's cameras: orthographic or not.
    pub cameras: Vec<bool>,
    /// The glTF camera on screen, if any.
    pub camera: Option<usize>,
    /// The viewer's own camera projects in parallel.
    pub orthographic: bool,
    /// The animation clock's label (None without animations).
    pub animation: Option<String>,
    /// The last pick's report.
    pub pick: Option<&'a str>,
    /// The glTF scene tree (None for built-in scenes).
    pub tree: Option<&'a SceneTree>,
    /// The node selected in the tree.
    pub selected: Option<usize>,
    /// The last load or reload's message (an error keeps the previous scene).
    pub status: Option<&'a str>,
    /// The shadow error budget in force, if any (`--shadow-budget`).
    pub budget: Option<f64>,
}

/// What a panel widget asks the viewer to do.
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    /// Change a view setting (the same actions the keys apply).
    Set(Action),
    /// Toggle shadows (`H`).
    ToggleShadows,
    /// Toggle the depth fit (`G`).
    ToggleDepthFit,
    /// Toggle soft shadows (`J`).
    ToggleSoft,
    /// The light the shadow views show (None: the first shadowed).
    ShadowLight(Option<usize>),
    /// Frame the scene (`F`).
    Frame,
    /// Look through a glTF camera (None: the viewer's own).
    Camera(Option<usize>),
    /// Perspective ↔ orthographic (`O`).
    ToggleOrthographic,
    /// Orbit ↔ fly (`Tab`).
    ToggleFly,
    /// Play / pause (`Space`).
    PlayPause,
    /// Step the animation by frames (`U`, `I`).
    Step(i32),
    /// Next animation (`R`).
    NextAnimation,
    /// Select a node of the tree and frame it.
    SelectNode(usize),
    /// The error budget (None: off).
    Budget(Option<f64>),
    /// Save a screenshot (`P`).
    Screenshot,
}

/// Widget rectangles by name, for scripted clicks (`ui:NAME`).
#[derive(Clone, Debug, Default)]
pub struct Widgets(pub HashMap<String, egui::Rect>);

impl Widgets {
    fn add(&mut self, name: impl Into<String>, r: &egui::Response) {
        self.0.insert(name.into(), r.rect);
    }
}

/// Shadow-map sides offered (the `[` `]` keys step through them).
const MAP_SIZES: [u32; 8] = [64, 128, 256, 512, 1024, 2048, 4096, 8192];

/// Error budgets offered (misclassified pixels, %; 0 takes exact shadows).
const BUDGETS: [f64; 5] = [0.0, 0.05, 0.1, 0.2, 0.5];

/// The keys, for the legend.
const KEYS: [(&str, &str); 25] = [
    ("F1", "panel on/off"),
    ("left drag / right drag / wheel", "orbit / pan / zoom"),
    ("click", "pick"),
    ("F", "frame the scene"),
    ("Tab", "orbit / fly (WASD, Q/E, Shift)"),
    ("C", "next glTF camera"),
    ("O", "perspective / orthographic"),
    ("arrows", "sun azimuth / elevation"),
    ("[ ]", "shadow map ½ / ×2"),
    ("M", "shadow maps / exact shadows"),
    ("B", "contact shadows"),
    ("K", "PCF kernel"),
    ("N", "cascades"),
    ("G", "depth fit"),
    ("J", "soft shadows"),
    ("L", "light shown"),
    ("+ -", "biases ×1.25 / ÷1.25"),
    ("T", "tone curve"),
    ("Y", "FXAA on/off"),
    (", .", "exposure −½ / +½ stop"),
    ("V", "view mode"),
    ("H", "shadows on/off"),
    ("P", "screenshot"),
    ("Space U I Z X R", "play, step −/+, speed, next animation"),
    ("Esc", "quit"),
];

/// Builds the panel on the right of `ui` (the whole window), appending what its widgets ask
/// for to `out` and their rectangles to `widgets`.
pub fn panel(ui: &mut egui::Ui, m: &PanelModel, out: &mut Vec<Command>, widgets: &mut Widgets) {
    egui::Panel::right("umbra panel")
        .default_size(260.0)
        .show(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| {
                ui.heading(m.scene);
                if let Some(s) = m.status {
                    ui.colored_label(egui::Color32::from_rgb(230, 150, 60), s);
                }
                frame_section(ui, m);
                pick_section(ui, m);
                shadow_section(ui, m, out, widgets);
                light_section(ui, m, out, widgets);
                camera_section(ui, m, out, widgets);
                if m.animation.is_some() {
                    animation_section(ui, m, out, widgets);
                }
                if let Some(t) = m.tree {
                    tree_section(ui, t, m.selected, out, widgets);
                }
                egui::CollapsingHeader::new("Keys").show(ui, |ui| {
                    egui::Grid::new("keys").striped(true).show(ui, |ui| {
                        for (k, what) in KEYS {
                            ui.monospace(k);
                            ui.label(what);
                            ui.end_row();
                        }
                    });
                });
            });
        });
}

fn frame_section(ui: &mut egui::Ui, m: &PanelModel) {
    let s = m.stats;
    egui::CollapsingHeader::new("Frame")
        .default_open(true)
        .show(ui, |ui| {
            egui::Grid::new("frame").show(ui, |ui| {
                let mut row = |k: &str, v: String| {
                    ui.label(k);
                    ui.monospace(v);
                    ui.end_row();
                };
                if s.fps > 0.0 {
                    row("fps", format!("{:.1}", s.fps));
                    row("CPU", format!("{:.2} ms", s.cpu_ms));
                } else {
                    row("fps", "measuring…".into());
                }
                match s.gpu_ms {
                    Some((a, b)) => {
                        row("GPU shadow", format!("{a:.2} ms"));
                        row("GPU camera", format!("{b:.2} ms"));
                    }
                    None => row("GPU", "n/a".into()),
                }
                row("triangles", s.triangles.to_string());
                row(
                    "draws",
                    format!("{} ({} deferred)", s.summary.draws, s.summary.deferred),
                );
                row("casters drawn", s.summary.casters.to_string());
                row("shadow views", s.summary.shadow_views.len().to_string());
            });
            if !s.summary.shadow_views.is_empty() {
                ui.label("view: light · texels · texel size");
            }
            for (i, &(light, res, texel)) in s.summary.shadow_views.iter().enumerate() {
                ui.monospace(format!("{i}: {light} · {res}² · {}", short(texel)));
            }
        });
}

fn shadow_section(ui: &mut egui::Ui, m: &PanelModel, out: &mut Vec<Command>, w: &mut Widgets) {
    let s = &m.view.shadow;
    egui::CollapsingHeader::new("Shadows")
        .default_open(true)
        .show(ui, |ui| {
            let mut on = s.enabled;
            let r = ui.checkbox(&mut on, "shadows (H)");
            w.add("shadows", &r);
            if r.changed() {
                out.push(Command::ToggleShadows);
            }
            let sizes = MAP_SIZES.map(|n| (n, n.to_string()));
            if let Some(n) = choice(ui, w, "map size ([ ])", "map", s.map_size, &sizes) {
                out.push(Command::Set(Action::SetMapSize(n)));
            }
            let methods = [
                (ShadowMethod::Map, "maps".to_string()),
                (ShadowMethod::Exact, "exact".into()),
                (ShadowMethod::Hybrid, "hybrid".into()),
            ];
            if let Some(m) = choice(ui, w, "shadow method (M)", "method", s.method, &methods) {
                out.push(Command::Set(Action::SetMethod(m)));
            }
            let kernels = [
                (Pcf::None, "none".to_string()),
                (Pcf::P2x2, "2x2".into()),
                (Pcf::P3x3, "3x3".into()),
                (Pcf::P5x5, "5x5".into()),
            ];
            if let Some(k) = choice(ui, w, "filter (K)", "pcf", s.pcf, &kernels) {
                out.push(Command::Set(Action::SetPcf(k)));
            }
            let counts: Vec<(u32, String)> = (0..=MAX_CASCADES)
                .map(|n| (n, if n == 0 { "auto".into() } else { n.to_string() }))
                .collect();
            if let Some(n) = choice(ui, w, "cascades (N)", "cascades", s.cascades, &counts) {
                out.push(Command::Set(Action::SetCascades(n)));
            }
            let mut fit = s.depth_fit;
            let r = ui.checkbox(&mut fit, "fit cascades to the depths seen (G)");
            w.add("depth-fit", &r);
            if r.changed() {
                out.push(Command::ToggleDepthFit);
            }
            let mut contact = s.contact;
            let r = ui.checkbox(&mut contact, "contact shadows (B)");
            w.add("contact", &r);
            if r.changed() {
                out.push(Command::Set(Action::ToggleContact));
            }
            let mut soft = s.soft;
            let r = ui.checkbox(&mut soft, "soft shadows for lights with a size (J)");
            w.add("soft", &r);
            if r.changed() {
                out.push(Command::ToggleSoft);
            }
            biases(ui, m, out, w);
            budget(ui, m, out, w);
        });
}

fn biases(ui: &mut egui::Ui, m: &PanelModel, out: &mut Vec<Command>, w: &mut Widgets) {
    let s = &m.view.shadow;
    let (mut c, mut sl, mut n) = (s.constant_bias, s.slope_bias, s.normal_offset);
    let mut changed = false;
    for (v, name, label) in [
        (&mut c, "bias.constant", "constant bias (texels)"),
        (&mut sl, "bias.slope", "slope bias"),
        (&mut n, "bias.normal", "normal offset (texels)"),
    ] {
        let old = *v;
        let r = ui.add(egui::Slider::new(v, 0.0..=8.0).text(label));
        w.add(name, &r);
        changed |= moved(&r, *v, old);
    }
    let r = ui.button("biases ×1.25 (+)");
    w.add("bias.up", &r);
    if r.clicked() {
        out.push(Command::Set(Action::BiasUp));
    } else if changed {
        out.push(Command::Set(Action::SetBiases(c, sl, n)));
    }
}

fn budget(ui: &mut egui::Ui, m: &PanelModel, out: &mut Vec<Command>, w: &mut Widgets) {
    let options: Vec<(Option<f64>, String)> = std::iter::once((None, "off".to_string()))
        .chain(BUDGETS.map(|b| (Some(b), b.to_string())))
        .collect();
    let label = "error budget (misclassified pixels, %)";
    if let Some(b) = choice(ui, w, label, "budget", m.budget, &options) {
        out.push(Command::Budget(b));
    }
}

/// A labelled row of mutually exclusive options (value, name): each registered as
/// `PREFIX.NAME`; the value clicked when it is not the `current` one.
fn choice<T: PartialEq + Clone>(
    ui: &mut egui::Ui,
    w: &mut Widgets,
    label: &str,
    prefix: &str,
    current: T,
    options: &[(T, String)],
) -> Option<T> {
    ui.label(label);
    let mut picked = None;
    ui.horizontal_wrapped(|ui| {
        for (value, name) in options {
            let r = ui.selectable_label(*value == current, name.as_str());
            w.add(format!("{prefix}.{name}"), &r);
            if r.clicked() && *value != current {
                picked = Some(value.clone());
            }
        }
    });
    picked
}

fn light_section(ui: &mut egui::Ui, m: &PanelModel, out: &mut Vec<Command>, w: &mut Widgets) {
    let v = m.view;
    egui::CollapsingHeader::new("Light and image")
        .default_open(true)
        .show(ui, |ui| {
            let mut sun = m.sun;
            let r1 =
                ui.add(egui::Slider::new(&mut sun.elevation, -90.0..=90.0).text("sun elevation °"));
            let r2 =
                ui.add(egui::Slider::new(&mut sun.azimuth, -180.0..=180.0).text("sun azimuth °"));
            w.add("sun.elevation", &r1);
            w.add("sun.azimuth", &r2);
            if moved(&r1, sun.elevation, m.sun.elevation) || moved(&r2, sun.azimuth, m.sun.azimuth)
            {
                out.push(Command::Set(Action::SetSun(sun)));
            }
            let lights: Vec<(Option<usize>, String)> = std::iter::once((None, "first".into()))
                .chain((0..m.lights).map(|i| (Some(i), i.to_string())))
                .collect();
            if let Some(l) = choice(ui, w, "light shown (L)", "light", v.shown_light, &lights) {
                out.push(Command::ShadowLight(l));
            }
            let mut ev = v.exposure_compensation;
            let r = ui.add(egui::Slider::new(&mut ev, -8.0..=8.0).text("exposure (EV, , .)"));
            w.add("exposure", &r);
            if moved(&r, ev, v.exposure_compensation) {
                out.push(Command::Set(Action::SetExposure(ev)));
            }
            let curves = [
                (Tonemap::Neutral, "neutral".to_string()),
                (Tonemap::Aces, "aces".into()),
                (Tonemap::None, "none".into()),
            ];
            if let Some(t) = choice(ui, w, "tone curve (T)", "tonemap", v.tonemap, &curves) {
                out.push(Command::Set(Action::SetTonemap(t)));
            }
            let name = |m: umbra::plan::ViewMode| format!("{m:?}").to_lowercase();
            egui::ComboBox::from_label("view (V)")
                .selected_text(name(v.mode))
                .show_ui(ui, |ui| {
                    for mode in VIEW_CYCLE {
                        let r = ui.selectable_label(v.mode == mode, name(mode));
                        w.add(format!("view.{}", name(mode)), &r);
                        if r.clicked() && v.mode != mode {
                            out.push(Command::Set(Action::SetView(mode)));
                        }
                    }
                });
        });
}

fn camera_section(ui: &mut egui::Ui, m: &PanelModel, out: &mut Vec<Command>, w: &mut Widgets) {
    egui::CollapsingHeader::new("Camera")
        .default_open(true)
        .show(ui, |ui| {
            ui.horizontal_wrapped(|ui| {
                for (name, cmd) in [
                    ("frame (F)", Command::Frame),
                    ("orbit / fly (Tab)", Command::ToggleFly),
                    ("screenshot (P)", Command::Screenshot),
                ] {
                    let r = ui.button(name);
                    w.add(
                        format!("camera.{}", name.split(' ').next().unwrap_or("")),
                        &r,
                    );
                    if r.clicked() {
                        out.push(cmd);
                    }
                }
            });
            let mut ortho = m.orthographic;
            let r = ui.checkbox(&mut ortho, "orthographic (O)");
            w.add("orthographic", &r);
            if r.changed() {
                out.push(Command::ToggleOrthographic);
            }
            if !m.cameras.is_empty() {
                let cameras: Vec<(Option<usize>, String)> =
                    std::iter::once((None, "viewer".into()))
                        .chain(m.cameras.iter().enumerate().map(|(i, &ortho)| {
                            (Some(i), format!("{i}{}", if ortho { "-ortho" } else { "" }))
                        }))
                        .collect();
                if let Some(c) = choice(ui, w, "glTF cameras (C)", "camera", m.camera, &cameras) {
                    out.push(Command::Camera(c));
                }
            }
        });
}

fn animation_section(ui: &mut egui::Ui, m: &PanelModel, out: &mut Vec<Command>, w: &mut Widgets) {
    egui::CollapsingHeader::new("Animation")
        .default_open(true)
        .show(ui, |ui| {
            if let Some(label) = &m.animation {
                ui.monospace(label);
            }
            ui.horizontal(|ui| {
                for (name, cmd) in [
                    ("play/pause", Command::PlayPause),
                    ("-1 frame", Command::Step(-1)),
                    ("+1 frame", Command::Step(1)),
                    ("next", Command::NextAnimation),
                ] {
                    let r = ui.button(name);
                    w.add(format!("anim.{name}"), &r);
                    if r.clicked() {
                        out.push(cmd);
                    }
                }
            });
        });
}

/// The last pick's report, near the top while there is one (what was just clicked).
fn pick_section(ui: &mut egui::Ui, m: &PanelModel) {
    let Some(text) = m.pick else {
        ui.label("click the scene to pick a surface");
        return;
    };
    egui::CollapsingHeader::new("Pick")
        .default_open(true)
        .show(ui, |ui| {
            for line in text.lines() {
                ui.label(
                    egui::RichText::new(line.trim_start_matches("pick: ").trim())
                        .monospace()
                        .size(11.0),
                );
            }
        });
}

fn tree_section(
    ui: &mut egui::Ui,
    t: &SceneTree,
    selected: Option<usize>,
    out: &mut Vec<Command>,
    w: &mut Widgets,
) {
    egui::CollapsingHeader::new(format!("Scene tree ({} nodes)", t.nodes.len()))
        .default_open(t.nodes.len() <= 40)
        .show(ui, |ui| {
            for &r in &t.roots {
                node_row(ui, t, r, selected, out, w, 0);
            }
        });
}

fn node_row(
    ui: &mut egui::Ui,
    t: &SceneTree,
    i: usize,
    selected: Option<usize>,
    out: &mut Vec<Command>,
    w: &mut Widgets,
    depth: usize,
) {
    let Some(n) = t.nodes.get(i) else { return };
    // Deep or cyclic hierarchies stop here (the loader refuses cycles; this is a UI bound).
    if depth > 32 {
        return;
    }
    let label = n.label(i);
    if n.children.is_empty() {
        let r = ui.selectable_label(selected == Some(i), label);
        w.add(format!("node.{i}"), &r);
        if r.clicked() {
            out.push(Command::SelectNode(i));
        }
        return;
    }
    let id = ui.make_persistent_id(("node", i));
    egui::collapsing_header::CollapsingState::load_with_default_open(ui.ctx(), id, depth < 2)
        .show_header(ui, |ui| {
            let r = ui.selectable_label(selected == Some(i), label);
            w.add(format!("node.{i}"), &r);
            if r.clicked() {
                out.push(Command::SelectNode(i));
            }
        })
        .body(|ui| {
            for &c in &n.children {
                node_row(ui, t, c, selected, out, w, depth + 1);
            }
        });
}

/// Whether a slider was moved by the user (a value only rounded for display is not a change).
fn moved(r: &egui::Response, new: f32, old: f32) -> bool {
    r.changed() && (new - old).abs() > 1e-4 * old.abs().max(1.0)
}

/// A length in few digits (texel sizes span 1e-6 to 1e3).
fn short(x: f32) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    format!("{x:.2e}")
}
