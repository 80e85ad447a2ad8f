//! `bench`'s schedule model: how fast a render would run on a host with
//! more cores than this one, from its work items measured here.
//!
//! A render is a serial part (building the firmware and the scene image,
//! assembling, putting the image together) and independent work items (its
//! chip instances), which the host's threads take from a work-stealing
//! pool. The model takes the items in order, each by the first thread to
//! be free (list scheduling, which a work-stealing pool approaches), so
//! the items' makespan on `n` threads is at least the longest item and at
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
