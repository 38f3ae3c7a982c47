//! A whole sweep over scenes and views, as `umbra sweep` runs it: the runs not yet in the
//! folder's `sweep.csv` (so an interrupted sweep resumes), then `sweep.json` and the Pareto
//! charts, and on request the error-budget model's features, its fit, and budget checks against
//! the sweep. The command line only parses its arguments and prints.

use super::budget::{self, CheckRow};
use super::chart::{self, ChartError};
use super::grid::{sweep_views, Config};
use super::sweep::{self, CsvAppender, Row, Sink, SweepIoError, SweepOptions, SweepView};
use crate::reference::ReferenceScene;
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use umbra::gpu::{Context, GpuError};
use umbra::render::Renderer;
use umbra::scene::{Camera, Scene};

/// What went wrong in a sweep.
#[derive(Debug, thiserror::Error)]
pub enum CampaignError {
    /// Rendering failed.
    #[error(transparent)]
    Gpu(#[from] GpuError),
    /// Reading or writing the sweep's CSV or JSON failed.
    #[error(transparent)]
    Files(#[from] SweepIoError),
    /// A chart could not be written.
    #[error(transparent)]
    Chart(#[from] ChartError),
    /// Another output file could not be written.
    #[error("writing {path}: {message}")]
    Write {
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
}

/// The runs of a sweep: each scene's views and the configurations measured in each, with the
/// runs its output folder already holds.
pub struct Campaign<'a> {
    /// The scenes.
    pub scenes: &'a [Scene],
    /// Per scene, its named views.
    pub views: Vec<Vec<(String, Camera)>>,
    /// The configurations measured in every view.
    pub configs: Vec<Config>,
    /// How each configuration is measured (image size, repeats, light size).
    pub opts: SweepOptions,
    /// The output folder.
    pub out: PathBuf,
    /// The (scene, view, configuration) keys already in `sweep.csv`.
    pub done: HashSet<(String, String, String)>,
}

/// What a sweep reports as it goes.
pub enum Progress<'a> {
    /// Now measuring this scene / view.
    View(&'a str, &'a str),
    /// One configuration scored, or timed once.
    Tick,
}

impl<'a> Campaign<'a> {
    /// The sweep of `configs` over the first `views_per_scene` sweep views of each scene, writing
    /// into `out` (created if needed; its `sweep.csv` says what is already done).
    pub fn new(
        scenes: &'a [Scene],
        configs: Vec<Config>,
        views_per_scene: usize,
        opts: SweepOptions,
        out: &Path,
    ) -> Result<Self, CampaignError> {
        std::fs::create_dir_all(out).map_err(|e| write_error(out, e))?;
        let aspect = opts.width as f32 / opts.height.max(1) as f32;
        let views = scenes
            .iter()
            .map(|s| {
                let mut v = sweep_views(s, aspect);
                v.truncate(views_per_scene.max(1));
                v
            })
            .collect();
        let done = sweep::read_csv(&out.join("sweep.csv"))?
            .iter()
            .map(Row::key)
            .collect();
        Ok(Self {
            scenes,
            views,
            configs,
            opts,
            out: out.to_path_buf(),
            done,
        })
    }

    /// The results file.
    pub fn csv_path(&self) -> PathBuf {
        self.out.join("sweep.csv")
    }

    /// Every run of the sweep.
    pub fn total(&self) -> usize {
        self.views
            .iter()
            .map(|v| v.len() * self.configs.len())
            .sum()
    }

    /// The runs already in `sweep.csv`.
    pub fn already(&self) -> usize {
        self.scenes_views()
            .flat_map(|(s, v)| self.configs.iter().map(move |c| self.key(s, &v.0, c)))
            .filter(|k| self.done.contains(k))
            .count()
    }

    /// Progress ticks the remaining runs make (`Progress::Tick`).
    pub fn ticks_left(&self) -> u64 {
        (self.total() - self.already()) as u64 * (self.opts.repeat.max(1) as u64 + 1)
    }

    fn scenes_views(&self) -> impl Iterator<Item = (&Scene, &(String, Camera))> {
        self.scenes
            .iter()
            .zip(&self.views)
            .flat_map(|(s, vs)| vs.iter().map(move |v| (s, v)))
    }

    fn key(&self, scene: &Scene, view: &str, c: &Config) -> (String, String, String) {
        (scene.name.clone(), view.to_string(), c.name())
    }

    /// Measures every run not yet in `sweep.csv` and appends its row there.
    pub fn run(
        &self,
        ctx: &Arc<Context>,
        progress: &mut dyn FnMut(Progress),
    ) -> Result<(), CampaignError> {
        let mut out = CsvAppender::open(&self.csv_path())?;
        let mut failed: Option<SweepIoError> = None;
        for (scene, vs) in self.scenes.iter().zip(&self.views) {
            let pending = |v: &str| {
                self.configs
                    .iter()
                    .any(|c| !self.done.contains(&self.key(scene, v, c)))
            };
            if !vs.iter().any(|v| pending(&v.0)) {
                continue;
            }
            let mut renderer = Renderer::with_options(ctx, scene, &Default::default())?;
            let reference = ReferenceScene::new(scene);
            for (name, camera) in vs {
                progress(Progress::View(&scene.name, name));
                let skip = |c: &str| {
                    self.done
                        .contains(&(scene.name.clone(), name.clone(), c.to_string()))
                };
                let mut on_row = |r: Row| {
                    if failed.is_none() {
                        failed = out.push(&r).err();
                    }
                };
                let view = SweepView {
                    scene: &scene.name,
                    name,
                    camera: *camera,
                };
                let mut tick = || progress(Progress::Tick);
                let mut sink = Sink {
                    on_row: &mut on_row,
                    tick: &mut tick,
                };
                sweep::run_view(
                    &mut renderer,
                    &reference,
                    &view,
                    &self.configs,
                    &self.opts,
                    &skip,
                    &mut sink,
                )?;
                if let Some(e) = failed.take() {
                    return Err(e.into());
                }
            }
        }
        Ok(())
    }

    /// Reads back every row of `sweep.csv` and writes `sweep.json`, a Pareto chart per scene
    /// (`pareto-NAME.svg/.png`) and one over all of them (`pareto.svg/.png`). Returns the rows
    /// and the scenes' names, in the order they first appear.
    pub fn write_results(&self) -> Result<(Vec<Row>, Vec<String>), CampaignError> {
        let rows = sweep::read_csv(&self.csv_path())?;
        sweep::write_json(&self.out.join("sweep.json"), &rows)?;
        let mut names: Vec<String> = Vec::new();
        for r in &rows {
            if !names.contains(&r.scene) {
                names.push(r.scene.clone());
            }
        }
        for n in &names {
            let of: Vec<Row> = rows.iter().filter(|r| &r.scene == n).cloned().collect();
            let views = of.iter().map(|r| &r.view).collect::<HashSet<_>>().len();
            let file = n.replace(|c: char| !c.is_ascii_alphanumeric() && c != '-', "_");
            chart::write_pareto(
                &sweep::mean_by_config(&of),
                &format!("{n}: mean over {views} view(s)"),
                &self.out.join(format!("pareto-{file}.svg")),
                &self.out.join(format!("pareto-{file}.png")),
            )?;
        }
        chart::write_pareto(
            &sweep::mean_by_config(&rows),
            &format!("all scenes ({}): mean over every view", names.join(", ")),
            &self.out.join("pareto.svg"),
            &self.out.join("pareto.png"),
        )?;
        Ok((rows, names))
    }

    /// Writes the error-budget model's features of every configuration of `all` in every view
    /// (`budget-features.csv`), and with `fit` the model fitted to them (`budget-model.rs`, its
    /// header naming the swept scenes `names`, the image size and the device `fit` names).
    pub fn write_features(
        &self,
        all: &[Config],
        (rows, names): (&[Row], &[String]),
        fit: Option<&str>,
    ) -> Result<(), CampaignError> {
        let mut feats = Vec::new();
        for (scene, vs) in self.scenes.iter().zip(&self.views) {
            let reference = ReferenceScene::new(scene);
            feats.extend(budget::feature_rows(&reference, scene, vs, all, rows));
        }
        write_csv(&self.out.join("budget-features.csv"), &feats)?;
        if let Some(device) = fit {
            let provenance = format!(
                "Fitted to {} rows of {} (sweep.csv) at {}x{} on {device}.",
                feats.len(),
                names.join(", "),
                self.opts.width,
                self.opts.height,
            );
            let p = self.out.join("budget-model.rs");
            std::fs::write(&p, budget::fit_model(&feats, rows, &provenance))
                .map_err(|e| write_error(&p, e))?;
        }
        Ok(())
    }

    /// Runs the budget mode for every budget in every view and checks each choice against the
    /// sweep's `rows` (`budget::check_view`); writes `budget-check.csv` and hands each row to
    /// `report`.
    pub fn check_budgets(
        &self,
        ctx: &Arc<Context>,
        rows: &[Row],
        budgets: &[f64],
        report: &mut dyn FnMut(&CheckRow),
    ) -> Result<(), CampaignError> {
        let mut checks = Vec::new();
        let size = (self.opts.width, self.opts.height);
        for (scene, vs) in self.scenes.iter().zip(&self.views) {
            let mut renderer = Renderer::with_options(ctx, scene, &Default::default())?;
            let reference = ReferenceScene::new(scene);
            for (name, camera) in vs {
                for &b in budgets {
                    let view = (name.as_str(), *camera);
                    let checked =
                        budget::check_view(&mut renderer, &reference, scene, view, size, b, rows)?;
                    if let Some(row) = checked {
                        report(&row);
                        checks.push(row);
                    }
                }
            }
        }
        write_csv(&self.out.join("budget-check.csv"), &checks)
    }
}

fn write_csv<T: serde::Serialize>(path: &Path, rows: &[T]) -> Result<(), CampaignError> {
    let err = |e: csv::Error| CampaignError::Write {
        path: path.display().to_string(),
        message: e.to_string(),
    };
    let mut wr = csv::Writer::from_path(path).map_err(err)?;
    for r in rows {
        wr.serialize(r).map_err(err)?;
    }
    wr.flush().map_err(|e| write_error(path, e))
}

fn write_error(path: &Path, e: std::io::Error) -> CampaignError {
    CampaignError::Write {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}
