//! What the sweep runs: its tasks (each knob render alone, each size
//! chain in order) and a task's run of its chain.

use anyhow::Result;

use super::{Job, Point, SceneRef, SCENE_SIZE};

/// What a task of the sweep reads as it renders its chain.
pub(super) struct ChainRun<'a> {
    pub(super) pts: &'a [Point],
    pub(super) jobs: &'a [Job],
    pub(super) scenes: &'a [(SceneRef, firmware::scene::Scene)],
    /// Points per job (the progress bar's steps).
    pub(super) per_job: &'a [u64],
    pub(super) bar: &'a indicatif::ProgressBar,
    pub(super) skipped: &'a std::sync::atomic::AtomicUsize,
    pub(super) size_seconds: f64,
}

impl ChainRun<'_> {
    /// The renders of one task's chain in order, by `measure` (a point,
    /// the task, the step): a render that fails is reported and skipped,
    /// and the sizes after one that took longer than --size-seconds are
    /// skipped.
    pub(super) fn chain(
        &self,
        chain: &[usize],
        task: usize,
        measure: &(dyn Fn(&Point, usize, usize) -> Result<serde_json::Value> + Sync),
    ) -> Vec<(usize, Option<serde_json::Value>)> {
        let mut out = Vec::new();
        // A size that took longer than --size-seconds: (size, seconds).
        let mut slow: Option<(u32, f64)> = None;
        for (step, &k) in chain.iter().enumerate() {
            let p = &self.pts[self.jobs[k].point];
            let sc = &self.scenes[p.scene].0;
            let c = &p.cfg;
            if let Some((size, t)) = slow {
                self.bar.suspend(|| {
                    eprintln!(
                        "skipped {} with the {} traversal: size {size} took {t:.0} s (--size-seconds {})",
                        sc.name,
                        c.opt.traversal.name(),
                        self.size_seconds
                    )
                });
                self.skipped
                    .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                self.bar.inc(self.per_job[k]);
                out.push((k, None));
                continue;
            }
            let r = match measure(p, task, step) {
                Ok(j) => Some(j),
                Err(e) => {
                    // A configuration the chip cannot run (for
                    // example a BSP too large for the FB) is
                    // reported and skipped.
                    self.bar.suspend(|| {
                        eprintln!("skipped {} with {}={}: {e:#}", sc.name, c.knob, c.value)
                    });
                    self.skipped
                        .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    None
                }
            };
            if let (Some(j), Some(_)) = (&r, &sc.family) {
                let t = j["host_chip_seconds"]
                    .as_f64()
                    .or_else(|| j["host_seconds"].as_f64())
                    .unwrap_or(0.0);
                if c.knob == SCENE_SIZE && t > self.size_seconds {
                    slow = Some((sc.size.unwrap_or(0), t));
                }
            }
            self.bar.inc(self.per_job[k]);
            out.push((k, r));
        }
        out
    }
}

/// What runs: each render of the knob sweep on its own, and each chain
/// of the size sweep (a family with one traversal, its sizes in order)
/// as one task that renders one size after the other and stops once a
/// render's chips took longer than --size-seconds (summed over
/// the threads, so about one thread's time, whatever runs beside it).
/// The tasks run concurrently on the thread pool, the chains first
/// (each render's work items share the pool), and the table takes
/// the renders in its own order: it is the one a render after another
/// gives.
pub(super) fn sweep_tasks(
    jobs: &[Job],
    pts: &[Point],
    scenes: &[(SceneRef, firmware::scene::Scene)],
) -> Vec<Vec<usize>> {
    let mut chains: Vec<((String, &str), Vec<usize>)> = Vec::new();
    let mut knob_jobs: Vec<usize> = Vec::new();
    for (k, job) in jobs.iter().enumerate() {
        let p = &pts[job.point];
        let sc = &scenes[p.scene].0;
        match sc.family.as_ref().filter(|_| p.cfg.knob == SCENE_SIZE) {
            Some(fam) => {
                let key = (fam.clone(), p.cfg.opt.traversal.name());
                match chains.iter_mut().find(|c| c.0 == key) {
                    Some(c) => c.1.push(k),
                    None => chains.push((key, vec![k])),
                }
            }
            None => knob_jobs.push(k),
        }
    }
    chains
        .into_iter()
        .map(|c| c.1)
        .chain(knob_jobs.into_iter().map(|k| vec![k]))
        .collect()
}
