//! `bench`'s schedule model: how fast a render would run on a host with
//! more cores than this one, from its work items measured here.
//!
//! A render is a serial part (building the firmware and the scene image,
//! assembling, putting the image together) and independent work items
//! (runs of its tiles, a chip each), which the host's threads take in
//! order, each by the first thread free. The items depend on the thread
//! count ([`crate::render::work_items`]): the model cuts the frame as `n`
//! threads would from the host seconds of each tile and of an item's own
//! work (building and loading its chip, its start-up), measured on one
//! thread ([`FrameWork`]), and takes the items in order, each by the first
//! thread to be free (list scheduling, as the render runs them), so the
//! items' makespan on `n` threads is at least the longest item and at
//! least their sum over `n`; the predicted time is the serial part plus
//! that makespan. On this machine the model's prediction for its own
//! thread count is printed beside the measured figure, which checks it.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// The time `items` (host seconds each) take on `workers` threads that each
/// take the next item when they are free.
pub fn makespan(items: &[f64], workers: usize) -> f64 {
    let workers = workers.max(1);
    // When each thread is free, in nanoseconds (an integer order).
    let mut free: BinaryHeap<Reverse<u64>> = (0..workers).map(|_| Reverse(0)).collect();
    let mut end = 0u64;
    for &t in items {
        let Reverse(at) = free.pop().unwrap_or(Reverse(0));
        let done = at + (t.max(0.0) * 1e9).round() as u64;
        end = end.max(done);
        free.push(Reverse(done));
    }
    end as f64 / 1e9
}

/// The predicted speed-up on `workers` threads of work that is `serial`
/// seconds of one thread and then `items` shared by the threads, against
/// one thread.
pub fn speedup(serial: f64, items: &[f64], workers: usize) -> f64 {
    let one = serial + items.iter().sum::<f64>();
    let many = serial + makespan(items, workers);
    if many > 0.0 {
        one / many
    } else {
        1.0
    }
}

/// A frame's chip render as measured: the host seconds of each tile (in
/// the chip's order) and of a work item's own work apart from its tiles.
#[derive(Clone, Debug, Default)]
pub struct FrameWork {
    pub tiles: Vec<f64>,
    pub item: f64,
}

impl FrameWork {
    /// A chip render's host work as measured: its tiles' seconds and a
    /// work item's own.
    pub fn of(r: &crate::render::ChipRender) -> FrameWork {
        FrameWork {
            tiles: r.tile_seconds.clone(),
            item: r.item_own_seconds,
        }
    }

    /// The work items `workers` threads run the frame as, in order: each
    /// the item's own work, its tiles and the warm-up tile before them.
    pub fn items(&self, workers: usize) -> Vec<f64> {
        crate::render::work_items(self.tiles.len(), workers, false)
            .into_iter()
            .map(|own| {
                let warm = own.start.checked_sub(1).map_or(0.0, |k| self.tiles[k]);
                self.item + warm + self.tiles[own].iter().sum::<f64>()
            })
            .collect()
    }
}

/// The predicted speed-up on `workers` threads of a frame's chip render:
/// `serial` seconds of one thread, then the frame's items on `workers`
/// threads, against its one item on one thread.
pub fn frame_speedup(serial: f64, frame: &FrameWork, workers: usize) -> f64 {
    let one = serial + frame.items(1).iter().sum::<f64>();
    let many = serial + makespan(&frame.items(workers), workers);
    if many > 0.0 {
        one / many
    } else {
        1.0
    }
}

/// A render of a sweep as measured on one thread: its task and place in it
/// ([`RenderWork`]), its preparation, and its chip render.
#[derive(Clone, Debug)]
pub struct RecordedRender {
    pub task: usize,
    pub step: usize,
    pub prep: f64,
    pub frame: FrameWork,
}

impl RecordedRender {
    /// The render as `workers` threads run it.
    pub fn on(&self, workers: usize) -> RenderWork {
        RenderWork {
            task: self.task,
            step: self.step,
            prep: self.prep,
            items: self.frame.items(workers),
        }
    }
}

/// One render of a sweep as the schedule model sees it: the task it
/// belongs to (a render of the knob sweep, or a chain of the size sweep
/// whose renders run one after the other), its place in that task, its
/// preparation (all but its chip render's items: the firmware, the probe,
/// the reference and the metrics; taken as one thread's work) and its work
/// items (host seconds each).
#[derive(Clone, Debug)]
pub struct RenderWork {
    pub task: usize,
    pub step: usize,
    pub prep: f64,
    pub items: Vec<f64>,
}

/// The time the renders of `work` take on `workers` threads: every task
/// starts at once; a render's preparation is one item, its work items
/// are ready when it ends, and the next render of its task when the last
/// of them ends. Each thread, when free, takes of the ready items the one
/// with the longest path of work still behind it in its task (critical
/// path first, as the sweep starts its size-sweep chains first and a
/// thread runs the items of its own render before others'; ties in
/// the order of the tasks); with none ready, the first to become ready.
pub fn sweep_makespan(work: &[RenderWork], workers: usize) -> f64 {
    let ns = |t: f64| (t.max(0.0) * 1e9).round() as u64;
    // The renders of each task, in order.
    let mut tasks: Vec<Vec<&RenderWork>> = Vec::new();
    for w in work {
        if tasks.len() <= w.task {
            tasks.resize(w.task + 1, Vec::new());
        }
        tasks[w.task].push(w);
    }
    for t in &mut tasks {
        t.sort_by_key(|w| w.step);
    }
    let longest = |w: &RenderWork| w.items.iter().map(|&t| ns(t)).max().unwrap_or(0);
    // The work behind each render of a task: the later renders' preparation
    // and longest item.
    let behind: Vec<Vec<u64>> = tasks
        .iter()
        .map(|renders| {
            let mut b = vec![0u64; renders.len()];
            for r in (0..renders.len().saturating_sub(1)).rev() {
                let next = renders[r + 1];
                b[r] = b[r + 1] + ns(next.prep) + longest(next);
            }
            b
        })
        .collect();
    // Released items: (ready at, priority, task, render, item or None
    // for the preparation).
    let mut ready: Vec<(u64, u64, usize, usize, Option<usize>)> = Vec::new();
    let release = |ready: &mut Vec<_>, at: u64, t: usize, r: usize, item: Option<usize>| {
        let w: &RenderWork = tasks[t][r];
        let prio = behind[t][r]
            + match item {
                None => ns(w.prep) + longest(w),
                Some(i) => ns(w.items[i]),
            };
        ready.push((at, prio, t, r, item));
    };
    for (t, renders) in tasks.iter().enumerate() {
        if !renders.is_empty() {
            release(&mut ready, 0, t, 0, None);
        }
    }
    // Per render: items not yet taken, and when the last taken ends.
    let mut left: Vec<Vec<(usize, u64)>> = tasks
        .iter()
        .map(|r| r.iter().map(|w| (w.items.len(), 0)).collect())
        .collect();
    let mut free: BinaryHeap<Reverse<u64>> = (0..workers.max(1)).map(|_| Reverse(0)).collect();
    let mut end = 0u64;
    while !ready.is_empty() {
        let Reverse(idle) = free.pop().unwrap_or(Reverse(0));
        // Of the items ready by `idle`, the longest path first; else the
        // first to become ready.
        let pick = (0..ready.len())
            .filter(|&k| ready[k].0 <= idle)
            .max_by_key(|&k| (ready[k].1, Reverse((ready[k].2, ready[k].3, ready[k].4))))
            .or_else(|| {
                (0..ready.len()).min_by_key(|&k| {
                    (
                        ready[k].0,
                        Reverse(ready[k].1),
                        ready[k].2,
                        ready[k].3,
                        ready[k].4,
                    )
                })
            });
        let Some(k) = pick else { break };
        let (at, _, t, r, item) = ready.swap_remove(k);
        let start = idle.max(at);
        let w = tasks[t][r];
        let done = start + ns(item.map_or(w.prep, |i| w.items[i]));
        free.push(Reverse(done));
        end = end.max(done);
        match item {
            None if w.items.is_empty() => {
                if r + 1 < tasks[t].len() {
                    release(&mut ready, done, t, r + 1, None);
                }
            }
            None => {
                for i in 0..w.items.len() {
                    release(&mut ready, done, t, r, Some(i));
                }
            }
            Some(_) => {
                let (n, last) = &mut left[t][r];
                *n -= 1;
                *last = (*last).max(done);
                if *n == 0 && r + 1 < tasks[t].len() {
                    let when = *last;
                    release(&mut ready, when, t, r + 1, None);
                }
            }
        }
    }
    end as f64 / 1e9
}

/// The predicted speed-up of a sweep on `workers` threads against one:
/// `serial` seconds of its own (loading scenes, the table and charts) and
/// its renders' work, as one thread and as `workers` threads run them
/// ([`sweep_makespan`]).
pub fn sweep_speedup(serial: f64, one: &[RenderWork], many: &[RenderWork], workers: usize) -> f64 {
    let one: f64 = serial
        + one
            .iter()
            .map(|w| w.prep + w.items.iter().sum::<f64>())
            .sum::<f64>();
    let many = serial + sweep_makespan(many, workers);
    if many > 0.0 {
        one / many
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every assignment of items to threads, the best makespan of them:
    /// list scheduling can do no better, and (Graham) no worse than the
    /// sum over n plus the longest item.
    fn optimum(items: &[f64], workers: usize) -> f64 {
        let mut best = f64::INFINITY;
        let mut assign = vec![0usize; items.len()];
        loop {
            let mut load = vec![0.0; workers];
            for (k, &w) in assign.iter().enumerate() {
                load[w] += items[k];
            }
            best = best.min(load.iter().cloned().fold(0.0, f64::max));
            // The next assignment, counting in base `workers`.
            let mut k = 0;
            while k < assign.len() && assign[k] == workers - 1 {
                assign[k] = 0;
                k += 1;
            }
            if k == assign.len() {
                return best;
            }
            assign[k] += 1;
        }
    }

    #[test]
    fn list_scheduling_by_hand() {
        // Two threads: 3 and 1 start together; 1 ends at 1 and takes 2
        // (ends at 3), 3 ends at 3 and takes the other 2 (ends at 5).
        assert_eq!(makespan(&[3.0, 1.0, 2.0, 2.0], 2), 5.0);
        // The optimum puts 3 with 1 and the two 2s together: 4.
        assert_eq!(optimum(&[3.0, 1.0, 2.0, 2.0], 2), 4.0);
        assert_eq!(makespan(&[1.0; 8], 3), 3.0);
        assert_eq!(makespan(&[], 4), 0.0);
        assert_eq!(makespan(&[2.5], 64), 2.5);
        // Serial 1 s and four items of 1 s: 5 s on one thread, 2 s on four.
        assert_eq!(speedup(1.0, &[1.0; 4], 4), 2.5);
        assert_eq!(speedup(0.0, &[1.0; 4], 1), 1.0);
    }

    #[test]
    fn a_frame_cut_as_the_threads_would_by_hand() {
        // 64 tiles of 1 s, 0.5 s of an item's own work.
        let f = FrameWork {
            tiles: vec![1.0; 64],
            item: 0.5,
        };
        assert_eq!(f.items(1), vec![64.5]);
        // Two threads: each item the tiles left over two, at least 16 (32,
        // 16, 16), all but the first after a warm-up tile.
        let two = f.items(2);
        assert_eq!(two, vec![32.5, 17.5, 17.5]);
        // 32.5 | 17.5, then the second thread's next: 35.
        assert_eq!(frame_speedup(0.0, &f, 2), 64.5 / 35.0);
        assert_eq!(frame_speedup(1.0, &f, 1), 1.0);
    }

    fn render(task: usize, step: usize, prep: f64, items: &[f64]) -> RenderWork {
        RenderWork {
            task,
            step,
            prep,
            items: items.to_vec(),
        }
    }

    #[test]
    fn a_sweep_by_hand() {
        // A chain of two renders (preparation 1, items 2 and 2; then
        // preparation 1, one item of 3) and a knob render
        // (preparation 1, items 1 and 1).
        let work = [
            render(0, 0, 1.0, &[2.0, 2.0]),
            render(0, 1, 1.0, &[3.0]),
            render(1, 0, 1.0, &[1.0, 1.0]),
        ];
        // One thread: everything one after the other, 12.
        assert_eq!(sweep_makespan(&work, 1), 12.0);
        // Two threads: both preparations 0-1; the chain's items 1-3
        // on both (the longest path behind them); at 3 the chain's second
        // preparation (3-4) and a knob item (3-4); the chain's last
        // item 4-7 beside the other knob item 4-5.
        assert_eq!(sweep_makespan(&work, 2), 7.0);
        // Taken first come, first served, the knob's items would have
        // gone before the chain's second preparation: 4-5, then 5-8.
        // Many threads: the chain is the critical path, 1 + 2 + 1 + 3.
        assert_eq!(sweep_makespan(&work, 16), 7.0);
        assert_eq!(sweep_speedup(0.0, &work, &work, 16), 12.0 / 7.0);
        // Steps given out of order are taken in order.
        let swapped = [work[1].clone(), work[0].clone(), work[2].clone()];
        assert_eq!(sweep_makespan(&swapped, 16), 7.0);
    }

    /// Knob renders alone are independent: on one thread the sum, and
    /// never shorter than the longest render's preparation plus its
    /// longest item, nor than the work over the threads.
    #[test]
    fn independent_renders_within_bounds() {
        let mut x = 99u64;
        let mut rnd = || {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((x >> 40) % 1000 + 1) as f64 / 1000.0
        };
        for _ in 0..50 {
            let work: Vec<RenderWork> = (0..6)
                .map(|t| {
                    let n = (rnd() * 4.0) as usize + 1;
                    let items: Vec<f64> = (0..n).map(|_| rnd()).collect();
                    render(t, 0, rnd(), &items)
                })
                .collect();
            let sum: f64 = work
                .iter()
                .map(|w| w.prep + w.items.iter().sum::<f64>())
                .sum();
            assert!((sweep_makespan(&work, 1) - sum).abs() < 1e-6);
            for n in [2, 3, 8] {
                let m = sweep_makespan(&work, n);
                let path = work
                    .iter()
                    .map(|w| w.prep + w.items.iter().cloned().fold(0.0, f64::max))
                    .fold(0.0, f64::max);
                assert!(m >= path - 1e-6 && m >= sum / n as f64 - 1e-6, "{m} on {n}");
                assert!(m <= sum + 1e-6);
            }
        }
    }

    #[test]
    fn within_grahams_bound_of_the_optimum() {
        let mut x = 12345u64;
        for _ in 0..200 {
            let n = (x % 7 + 1) as usize;
            let items: Vec<f64> = (0..n)
                .map(|_| {
                    x = x
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    ((x >> 40) % 1000 + 1) as f64 / 100.0
                })
                .collect();
            for workers in 1..=3 {
                let got = makespan(&items, workers);
                let opt = optimum(&items, workers);
                let sum: f64 = items.iter().sum();
                let longest = items.iter().cloned().fold(0.0, f64::max);
                assert!(got >= opt - 1e-9, "{items:?} on {workers}: {got} < {opt}");
                assert!(
                    got <= sum / workers as f64 + longest * (1.0 - 1.0 / workers as f64) + 1e-6,
                    "{items:?} on {workers}: {got}"
                );
            }
        }
    }
}
