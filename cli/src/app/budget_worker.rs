//! The viewer's error budget: a thread with its own offscreen renderer and ray-cast reference
//! re-chooses the shadow settings (`analysis::budget::choose`) whenever the camera has moved, and
//! keeps the running choice unless it leaves the budget or a clearly cheaper one meets it
//! (`budget::keep_current`), so settings do not flicker.

use std::sync::mpsc::{channel, Receiver, Sender, TryRecvError};
use std::thread::JoinHandle;
use umbra::gpu::{Context, ContextDesc, Validation};
use umbra::{Renderer, Scene, View};
use umbra_lab::analysis::budget::{self, BudgetChoice};
use umbra_lab::analysis::grid::Config;

struct Request {
    view: View,
    size: (u32, u32),
    /// The running configuration and its relative cost when it was chosen.
    current: Option<(Config, f64)>,
}

/// A re-choice.
pub struct Outcome {
    /// What `choose` decided for the new view.
    pub choice: BudgetChoice,
    /// Whether the running configuration stays.
    pub kept: bool,
}

/// The worker thread and its channels.
pub struct BudgetWorker {
    tx: Option<Sender<Request>>,
    rx: Receiver<anyhow::Result<Outcome>>,
    thread: Option<JoinHandle<anyhow::Result<usize>>>,
    /// A request is being worked on.
    pub busy: bool,
    /// The camera of the last request.
    pub last_camera: Option<umbra::Camera>,
    /// The running choice and its cost.
    pub current: Option<(Config, f64)>,
}

impl BudgetWorker {
    /// Starts the thread for `budget` over (a copy of) `scene`.
    pub fn start(scene: Scene, budget: f64, device: Option<String>, validation: bool) -> Self {
        let (tx, req_rx) = channel::<Request>();
        let (out_tx, rx) = channel();
        let thread = std::thread::spawn(move || -> anyhow::Result<usize> {
            let ctx = Context::new(&ContextDesc {
                validation: Validation::required_if(validation),
                device,
                pipeline_cache: super::pipeline_cache_path(),
                ..Default::default()
            })?;
            let log = ctx.validation_log.clone();
            let mut renderer = Renderer::new(&ctx, &scene)?;
            let reference = umbra_lab::reference::ReferenceScene::new(&scene);
            while let Ok(r) = req_rx.recv() {
                let out = (|| -> anyhow::Result<Outcome> {
                    let (w, h) = r.size;
                    let running = r.current.as_ref().map(|c| &c.0);
                    let choice = budget::choose(
                        &mut renderer,
                        &reference,
                        &scene,
                        &r.view,
                        (w, h),
                        budget,
                        running,
                    )?
                    .ok_or_else(|| anyhow::anyhow!("no light casts a shadow"))?;
                    let kept = match (&r.current, choice.current_measured) {
                        (Some((c, cost)), Some(m)) if *c != choice.chosen.config => {
                            budget::keep_current(&choice, *cost, m)
                        }
                        _ => false,
                    };
                    Ok(Outcome { choice, kept })
                })();
                if out_tx.send(out).is_err() {
                    break;
                }
            }
            drop(reference);
            drop(renderer);
            drop(ctx);
            Ok(log.problem_count())
        });
        Self {
            tx: Some(tx),
            rx,
            thread: Some(thread),
            busy: false,
            last_camera: None,
            current: None,
        }
    }

    /// Asks for a choice for `view` at `size` unless one is being made or the camera has not
    /// moved since the last request.
    pub fn request(&mut self, view: &View, size: (u32, u32)) {
        if self.busy || self.last_camera == Some(view.camera) || size.0 == 0 || size.1 == 0 {
            return;
        }
        if let Some(tx) = &self.tx {
            let current = self.current.clone();
            if tx
                .send(Request {
                    view: view.clone(),
                    size,
                    current,
                })
                .is_ok()
            {
                self.busy = true;
                self.last_camera = Some(view.camera);
            }
        }
    }

    /// A finished choice, if any (with `wait`, blocks until the pending one is made): applies it
    /// to `view` (unless the running one stays) and returns it.
    pub fn poll(&mut self, view: &mut View, wait: bool) -> anyhow::Result<Option<Outcome>> {
        let got = if wait && self.busy {
            self.rx.recv().map_err(|_| TryRecvError::Disconnected)
        } else {
            self.rx.try_recv()
        };
        match got {
            Ok(out) => {
                self.busy = false;
                let out = out?;
                if !out.kept {
                    view.shadow = out.choice.chosen.config.shadow;
                    self.current = Some((
                        out.choice.chosen.config.clone(),
                        out.choice.chosen.relative_cost,
                    ));
                }
                Ok(Some(out))
            }
            Err(TryRecvError::Empty) => Ok(None),
            Err(TryRecvError::Disconnected) => {
                self.busy = false;
                Ok(None)
            }
        }
    }

    /// Stops the thread; returns its validation messages of warning or error severity.
    pub fn finish(mut self) -> anyhow::Result<usize> {
        self.tx = None;
        match self.thread.take().map(|t| t.join()) {
            Some(Ok(r)) => r,
            Some(Err(_)) => anyhow::bail!("the shadow-budget thread panicked"),
            None => Ok(0),
        }
    }
}
