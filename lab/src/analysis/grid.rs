//! What a sweep runs: the shadow configurations of a grid, and the views of a scene.

use glam::Vec3;
use umbra::plan::{Pcf, ShadowFit, ShadowFormat, ShadowMethod, ShadowSettings};
use umbra::scene::{Camera, Scene};

/// Bias presets: (name, constant texels, slope, normal offset texels).
pub const BIAS_PRESETS: [(&str, f32, f32, f32); 3] = [
    ("low", 0.5, 0.75, 0.75),
    ("default", 1.0, 1.5, 1.5),
    ("high", 2.0, 3.0, 3.0),
];

/// One shadow configuration of a sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct Config {
    /// The settings rendered with.
    pub shadow: ShadowSettings,
    /// Name of its bias preset (`BIAS_PRESETS`).
    pub bias: &'static str,
    /// PCSS soft shadows for the lights' sizes (`shadow.soft`); the filter is named `pcss`.
    pub pcss: bool,
}

impl Config {
    /// Exact shadows (`ShadowMethod::Exact`) with a `map_size`² map for the pixels the exact
    /// pass does not judge.
    pub fn exact(map_size: u32) -> Self {
        Config {
            shadow: ShadowSettings {
                method: ShadowMethod::Exact,
                map_size,
                cascades: 1,
                soft: false,
                ..ShadowSettings::default()
            },
            bias: "default",
            pcss: false,
        }
    }

    /// Hybrid shadows (`ShadowMethod::Hybrid`): exact shadows' settings, the map's verdict kept
    /// where it is certain.
    pub fn hybrid(map_size: u32) -> Self {
        let mut c = Self::exact(map_size);
        c.shadow.method = ShadowMethod::Hybrid;
        c
    }

    /// The fitting method, the chart's colour: `scene`, `camera`, `cascades2`, `cascades4`…
    /// (`exact`, `hybrid`).
    pub fn method(&self) -> String {
        match self.shadow.method {
            ShadowMethod::Exact => return "exact".into(),
            ShadowMethod::Hybrid => return "hybrid".into(),
            ShadowMethod::Map => {}
        }
        if self.shadow.depth_fit {
            return format!("sdsm{}", self.shadow.cascades);
        }
        method_of(self.shadow.fit, self.shadow.cascades)
    }

    /// The filter: `pcss`, or the PCF kernel's name (`filter_name`).
    pub fn filter(&self) -> &'static str {
        if self.shadow.method == ShadowMethod::Exact {
            "exact"
        } else if self.shadow.method == ShadowMethod::Hybrid {
            "hybrid"
        } else if self.shadow.contact {
            "contact"
        } else if self.pcss {
            "pcss"
        } else {
            filter_name(self.shadow.pcf)
        }
    }

    /// A short unique name, e.g. `2048-d32-pcf2x2-cascades4-default`.
    pub fn name(&self) -> String {
        format!(
            "{}-{}-{}-{}-{}",
            self.shadow.map_size,
            format_name(self.shadow.format),
            self.filter(),
            self.method(),
            self.bias
        )
    }
}

/// The fitting method of a fit and cascade count (as in `Config::method`).
pub fn method_of(fit: ShadowFit, cascades: u32) -> String {
    match (fit, cascades) {
        (ShadowFit::Scene, _) => "scene".into(),
        (ShadowFit::Sphere, 0) => "sphere-auto".into(),
        (ShadowFit::Sphere, 1) => "sphere".into(),
        (ShadowFit::Sphere, n) => format!("sphere-cascades{n}"),
        (ShadowFit::Camera, 0) => "auto".into(),
        (ShadowFit::Camera, 1) => "camera".into(),
        (ShadowFit::Camera, n) => format!("cascades{n}"),
    }
}

/// `d16`, `d32` or `auto`.
pub fn format_name(f: ShadowFormat) -> &'static str {
    match f {
        ShadowFormat::D16 => "d16",
        ShadowFormat::D32 => "d32",
        ShadowFormat::Auto => "auto",
    }
}

/// `nearest`, `pcf2x2`, `pcf3x3`, `pcf5x5`.
pub fn filter_name(p: Pcf) -> &'static str {
    match p {
        Pcf::None => "nearest",
        Pcf::P2x2 => "pcf2x2",
        Pcf::P3x3 => "pcf3x3",
        Pcf::P5x5 => "pcf5x5",
    }
}

/// The axes of a configuration grid; every combination is one configuration (cascades only with
/// camera fitting).
#[derive(Clone, Debug)]
pub struct Grid {
    /// Map sizes in texels.
    pub maps: Vec<u32>,
    /// Depth formats.
    pub formats: Vec<ShadowFormat>,
    /// Filters.
    pub filters: Vec<Pcf>,
    /// Bias presets by name.
    pub biases: Vec<&'static str>,
    /// Fittings: (fit, cascades); cascades 1 = one map.
    pub fits: Vec<(ShadowFit, u32)>,
    /// Also 4 cascades fitted to the depths seen (`ShadowSettings::depth_fit`, method `sdsm4`),
    /// for every map, format, filter and bias.
    pub sdsm: bool,
    /// Also PCSS (filter `pcss`, for every map, format, bias and fitting), the other
    /// configurations then hard whatever the lights' sizes.
    pub pcss: bool,
    /// Also exact and hybrid shadows (`ShadowMethod::Exact` and `Hybrid`, method and filter
    /// `exact` and `hybrid`): a configuration each, at the largest map of `maps` (which only the
    /// pixels they do not trace read).
    pub exact: bool,
    /// Also contact shadows over the default maps (`ShadowSettings::contact`, filter
    /// `contact`): one configuration, at the largest map of `maps`.
    pub contact: bool,
}

impl Grid {
    /// The full grid: 6 map sizes × 2 formats × 4 filters × 3 bias presets × 4 fittings (scene,
    /// camera, 2 and 4 cascades) = 576 configurations.
    pub fn full() -> Self {
        Self {
            maps: vec![256, 512, 1024, 2048, 4096, 8192],
            formats: vec![ShadowFormat::D16, ShadowFormat::D32],
            filters: vec![Pcf::None, Pcf::P2x2, Pcf::P3x3, Pcf::P5x5],
            biases: BIAS_PRESETS.iter().map(|b| b.0).collect(),
            fits: vec![
                (ShadowFit::Scene, 1),
                (ShadowFit::Camera, 1),
                (ShadowFit::Camera, 2),
                (ShadowFit::Camera, 4),
            ],
            sdsm: false,
            pcss: false,
            exact: false,
            contact: false,
        }
    }

    /// The coarse grid of `--quick`: 4 map sizes × D32 × 3 filters × default bias × 4 fittings
    /// = 48 configurations.
    pub fn quick() -> Self {
        Self {
            maps: vec![512, 1024, 2048, 4096],
            formats: vec![ShadowFormat::D32],
            filters: vec![Pcf::None, Pcf::P2x2, Pcf::P5x5],
            biases: vec!["default"],
            ..Self::full()
        }
    }

    /// Every configuration, cheapest axes varying fastest.
    pub fn configs(&self) -> Vec<Config> {
        let mut out = Vec::new();
        let mut fits: Vec<(ShadowFit, u32, bool)> =
            self.fits.iter().map(|&(f, c)| (f, c, false)).collect();
        if self.sdsm {
            fits.push((ShadowFit::Camera, 4, true));
        }
        let mut filters: Vec<(Pcf, bool)> = self.filters.iter().map(|&p| (p, false)).collect();
        if self.pcss {
            filters.push((Pcf::P2x2, true));
        }
        for &(fit, cascades, depth_fit) in &fits {
            for &bias in &self.biases {
                let (_, c, s, n) = BIAS_PRESETS
                    .iter()
                    .copied()
                    .find(|b| b.0 == bias)
                    .unwrap_or(BIAS_PRESETS[1]);
                for &format in &self.formats {
                    for &(pcf, pcss) in &filters {
                        for &map_size in &self.maps {
                            out.push(Config {
                                shadow: ShadowSettings {
                                    enabled: true,
                                    map_size,
                                    format,
                                    pcf,
                                    constant_bias: c,
                                    slope_bias: s,
                                    normal_offset: n,
                                    fit,
                                    snap: true,
                                    cascades,
                                    cube_face: 0,
                                    depth_fit,
                                    soft: pcss || !self.pcss,
                                    ..ShadowSettings::default()
                                },
                                bias,
                                pcss,
                            });
                        }
                    }
                }
            }
        }
        let largest = self.maps.iter().copied().max().unwrap_or(2048);
        if self.exact {
            out.push(Config::exact(largest));
            out.push(Config::hybrid(largest));
        }
        if self.contact {
            out.push(Config {
                shadow: ShadowSettings {
                    contact: true,
                    map_size: largest,
                    soft: false,
                    ..ShadowSettings::default()
                },
                bias: "default",
                pcss: false,
            });
        }
        out
    }
}

/// The views a sweep renders a scene from: its glTF cameras (at most 4) named `camera0`…, else
/// `default` (the default camera), `high` (steeply from above, the other side) and `ground` (from
/// near the lowest point of the bounds, looking level across the scene: near and far receivers in
/// one image).
pub fn sweep_views(scene: &Scene, aspect: f32) -> Vec<(String, Camera)> {
    if !scene.cameras.is_empty() {
        return scene
            .cameras
            .iter()
            .take(4)
            .enumerate()
            .map(|(i, c)| (format!("camera{i}"), *c))
            .collect();
    }
    let b = scene.bounds();
    let default = scene.default_camera(aspect);
    if b.is_empty() {
        return vec![("default".into(), default)];
    }
    let framed = scene.framing.unwrap_or(b);
    let (c, r) = framed.bounding_sphere();
    let dist = (default.position() - c).length();
    let fov = umbra::scene::mesh::framing::FOV_Y_DEG.to_radians();
    let high = Camera::look_at(
        c + Vec3::new(-0.45, 1.3, -0.6).normalize() * dist,
        c,
        default.fov_y().unwrap_or(fov),
        default.near,
    );
    // Eye height: 4% of the framed model's height above the lowest point (at least 0.2% of r).
    let h = (framed.extent().y * 0.04).max(r * 2e-3);
    let eye = Vec3::new(c.x - 1.2 * r, b.min.y + h, c.z + 1.2 * r);
    let target = Vec3::new(c.x + 2.0 * r, b.min.y + h * 0.6, c.z - 2.0 * r);
    let ground = Camera::look_at(eye, target, 60f32.to_radians(), (h * 0.05).max(1e-4));
    vec![
        ("default".into(), default),
        ("high".into(), high),
        ("ground".into(), ground),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grids_have_the_documented_sizes_and_unique_names() {
        let full = Grid::full().configs();
        assert_eq!(full.len(), 576);
        assert_eq!(Grid::quick().configs().len(), 48);
        let mut names: Vec<String> = full.iter().map(Config::name).collect();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), 576, "names must identify configurations");
        assert!(full
            .iter()
            .any(|c| c.name() == "2048-d32-pcf2x2-camera-default"));
        // Every full-grid configuration keeps soft shadows for lights with a size.
        assert!(full.iter().all(|c| c.shadow.soft && !c.pcss));
    }

    #[test]
    fn depth_fitted_and_pcss_configurations_join_the_grid_on_request() {
        let g = Grid {
            sdsm: true,
            pcss: true,
            ..Grid::quick()
        };
        let all = g.configs();
        // 4 maps × (3 filters + PCSS) × (4 fittings + sdsm4).
        assert_eq!(all.len(), 80);
        let mut names: Vec<String> = all.iter().map(Config::name).collect();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), 80);
        let sdsm: Vec<_> = all.iter().filter(|c| c.method() == "sdsm4").collect();
        assert_eq!(sdsm.len(), 16);
        assert!(sdsm
            .iter()
            .all(|c| c.shadow.depth_fit && c.shadow.cascades == 4));
        // PCSS configurations are soft; the rest hard, whatever the lights' sizes.
        assert!(all.iter().all(|c| c.shadow.soft == (c.filter() == "pcss")));
        assert!(all
            .iter()
            .any(|c| c.name() == "2048-d32-pcss-sdsm4-default"));
    }

    #[test]
    fn exact_hybrid_and_contact_shadows_join_the_grid_as_one_configuration_each() {
        let g = Grid {
            exact: true,
            ..Grid::quick()
        };
        let all = g.configs();
        assert_eq!(all.len(), Grid::quick().configs().len() + 2);
        let exact: Vec<_> = all.iter().filter(|c| c.method() == "exact").collect();
        assert_eq!(exact.len(), 1);
        assert_eq!(exact[0].filter(), "exact");
        assert_eq!(exact[0].shadow.method, ShadowMethod::Exact);
        assert_eq!(exact[0].name(), "4096-auto-exact-exact-default");
        let hybrid: Vec<_> = all.iter().filter(|c| c.method() == "hybrid").collect();
        assert_eq!(hybrid.len(), 1);
        assert_eq!(hybrid[0].shadow.method, ShadowMethod::Hybrid);
        assert_eq!(hybrid[0].name(), "4096-auto-hybrid-hybrid-default");
        let g = Grid {
            contact: true,
            ..Grid::quick()
        };
        let last = g.configs().pop().unwrap();
        assert!(last.shadow.contact && !last.shadow.soft);
        assert_eq!(last.name(), "4096-auto-contact-auto-default");
    }

    #[test]
    fn views_of_a_scene_without_cameras_include_one_near_the_ground() {
        let mut s = umbra::scene::built::demo::demo_scene();
        s.cameras.clear();
        let v = sweep_views(&s, 16.0 / 9.0);
        assert_eq!(v.len(), 3);
        let b = s.bounds();
        let eye = v[2].1.position();
        assert!(eye.y - b.min.y < 0.1 * b.extent().y, "{eye} in {b:?}");
        assert_eq!(
            sweep_views(&umbra::scene::built::synthetic::town_scene(), 1.0).len(),
            2
        );
    }
}
