//! The status bar's exact `k_a` under the cursor, without stalling a frame: the exact
//! integral (45 ms to 3.5 s a value) runs on a worker thread, and its results are kept per
//! model and half-float code of `n` (the only values a map holds), so a texel's value is
//! integrated once. The UI thread never runs the integrator: it shows the value when it
//! arrives and asks for a repaint.

use std::collections::HashMap;
use std::sync::mpsc::{Receiver, Sender, channel};
use std::sync::{Arc, OnceLock};

use kapaint_reflectance::ShadingModel;
use kapaint_reflectance::exact::chi_parts_exact;

/// One value to integrate: a model and the half-float bits of `n`.
type Key = (ShadingModel, u16);

/// Exact `[chi_1(n), chi_0(n)]` values (`chi_0 = 0` but for Cook-Torrance), computed on a
/// worker and kept.
pub struct ExactChi {
    known: HashMap<Key, [f64; 2]>,
    asked: Option<Key>,
    requests: Option<Sender<Key>>,
    results: Receiver<(Key, [f64; 2])>,
    /// The context to repaint when a value arrives (known from the first frame on).
    ctx: Arc<OnceLock<egui::Context>>,
}

impl std::fmt::Debug for ExactChi {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ExactChi")
            .field("known", &self.known.len())
            .field("asked", &self.asked)
            .finish_non_exhaustive()
    }
}

impl ExactChi {
    /// Starts the worker. Without a thread (none could be started) values are never shown,
    /// and a frame still never integrates.
    pub fn new() -> Self {
        let (request_tx, request_rx) = channel::<Key>();
        let (result_tx, results) = channel();
        let ctx = Arc::new(OnceLock::<egui::Context>::new());
        let wake = Arc::clone(&ctx);
        let started = std::thread::Builder::new()
            .name("exact chi".into())
            .spawn(move || {
                while let Ok(mut key) = request_rx.recv() {
                    // Only the latest request matters: the cursor has moved on.
                    while let Ok(newer) = request_rx.try_recv() {
                        key = newer;
                    }
                    let n = half::f16::from_bits(key.1).to_f64();
                    if result_tx.send((key, chi_parts_exact(key.0, n))).is_err() {
                        return;
                    }
                    if let Some(ctx) = wake.get() {
                        ctx.request_repaint();
                    }
                }
            });
        Self {
            known: HashMap::new(),
            asked: None,
            requests: started.is_ok().then_some(request_tx),
            results,
            ctx,
        }
    }

    /// The exact `[chi_1, chi_0]` of `model` at the `n` whose half-float bits are `n_bits`, if
    /// it is known; else asks the worker for it (`ctx` is repainted when it arrives) and
    /// returns `None` for now.
    pub fn get(
        &mut self,
        ctx: &egui::Context,
        model: ShadingModel,
        n_bits: u16,
    ) -> Option<[f64; 2]> {
        self.ctx.get_or_init(|| ctx.clone());
        while let Ok((key, value)) = self.results.try_recv() {
            self.known.insert(key, value);
            if self.asked == Some(key) {
                self.asked = None;
            }
        }
        let key = (model, n_bits);
        if let Some(v) = self.known.get(&key) {
            return Some(*v);
        }
        if self.asked != Some(key)
            && let Some(tx) = &self.requests
            && tx.send(key).is_ok()
        {
            self.asked = Some(key);
        }
        None
    }
}

impl Default for ExactChi {
    fn default() -> Self {
        Self::new()
    }
}
