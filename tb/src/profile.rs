//! Where a frame's cycles go, for firmware authors: every cycle of the
//! tile loop is charged to the RC kernel the array executes in it or, when
//! the array idles, to the TinyRISC code (the label before its PC) that
//! keeps it waiting. `morphosys render --profile` prints the table for the
//! whole frame (the sum of its work items' tiles).

use std::collections::BTreeMap;

use firmware::asm::{Image, Section};
use rtl::rc::Word;
use rtl::{Chip, Sim};

/// Cycles charged to kernels (array busy) and to TinyRISC labels (array
/// idle), largest first.
#[derive(Clone, Debug, Default)]
pub struct Profile {
    pub cycles: u64,
    pub kernels: Vec<(String, u64)>,
    pub control: Vec<(String, u64)>,
}

impl Profile {
    /// The sum of two profiles (two work items of a frame).
    pub fn merge(a: Profile, b: Profile) -> Profile {
        let add = |x: Vec<(String, u64)>, y: Vec<(String, u64)>| {
            let mut m: BTreeMap<String, u64> = BTreeMap::new();
            for (n, c) in x.into_iter().chain(y) {
                *m.entry(n).or_default() += c;
            }
            sorted(m)
        };
        Profile {
            cycles: a.cycles + b.cycles,
            kernels: add(a.kernels, b.kernels),
            control: add(a.control, b.control),
        }
    }
}

/// The frame's cycles by cause ([`Profile::causes`]), in print order.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Causes {
    /// Object-test kernels, times the SIMD efficiency: the lanes whose
    /// ray needed the test.
    pub tests_needed: u64,
    /// Object-test kernels, times one minus the SIMD efficiency: the
    /// lanes whose ray does not reach the object's cell (divergence).
    pub divergence_waste: u64,
    /// Every other kernel: traversal (nodes, pushes, pops) and shading.
    pub traversal_and_shading: u64,
    /// The array idle while TinyRISC waits for the DMA channel.
    pub dma_wait: u64,
    /// The array idle while TinyRISC decides (nodes, leaves, mailboxes).
    pub control_idle: u64,
}

impl Profile {
    /// The cycles split by cause: busy cycles in the object tests' kernels
    /// (`tests`, the kernels of every primitive's test) are divided by
    /// `simd_efficiency` (the share of the broadcast tests' lanes whose ray
    /// needed them: one figure for every test, so each kernel's cycles are
    /// divided in the same proportion), the other busy cycles are
    /// traversal and shading; idle cycles are DMA waits (`dma_idle`, the
    /// cycles the array had no context while TinyRISC waited for the DMA,
    /// at most the idle cycles) or control.
    pub fn causes(&self, tests: &[String], simd_efficiency: f64, dma_idle: u64) -> Causes {
        let busy: u64 = self.kernels.iter().map(|x| x.1).sum();
        let test: u64 = self
            .kernels
            .iter()
            .filter(|(n, _)| tests.contains(n))
            .map(|x| x.1)
            .sum();
        let needed = (test as f64 * simd_efficiency.clamp(0.0, 1.0)).round() as u64;
        let idle = self.cycles.saturating_sub(busy);
        let dma = dma_idle.min(idle);
        Causes {
            tests_needed: needed,
            divergence_waste: test - needed,
            traversal_and_shading: busy - test,
            dma_wait: dma,
            control_idle: idle - dma,
        }
    }
}

fn sorted<K: ToString>(m: BTreeMap<K, u64>) -> Vec<(String, u64)> {
    let mut v: Vec<(String, u64)> = m.into_iter().map(|(n, x)| (n.to_string(), x)).collect();
    v.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    v
}

/// Maps context addresses to kernel names and TinyRISC addresses to the
/// code labels of the source.
pub struct Names {
    kernels: Vec<(u32, String)>,
    labels: Vec<(u32, String)>,
}

impl Names {
    pub fn new(img: &Image, ctx_base: u32) -> Names {
        // TinyRISC's code labels (the macros' included), and the kernels:
        // the context labels `k_NAME` (not their `k_NAME_end`, nor the
        // cuts `k_NAME_cut_C` and entries `k_NAME_from_E` inside them:
        // their cycles are the kernel's).
        let labels = img
            .labels_in(Section::Text)
            .map(|l| (l.addr, l.name.clone()))
            .collect();
        let kernels = img
            .labels_in(Section::Ctx)
            .filter(|l| {
                l.name.starts_with("k_")
                    && !l.name.ends_with("_end")
                    && !l.name.contains("_cut_")
                    && !l.name.contains("_from_")
                    && l.addr >= ctx_base
            })
            .map(|l| ((l.addr - ctx_base) / 4, l.name.clone()))
            .collect();
        Names { kernels, labels }
    }

    fn find(list: &[(u32, String)], a: u32) -> &str {
        match list.partition_point(|(x, _)| *x <= a) {
            0 => "?",
            i => &list[i - 1].1,
        }
    }
}

/// Step `sim` to its halt (an error past `max_cycles`), charging every cycle;
/// with `stop`, only until TinyRISC's PC comes to it (an arrival: the PC
/// is `stop` and was not in the cycle before), that cycle not run.
pub fn run<W: Word>(
    sim: &mut Sim<Chip<W>>,
    names: &Names,
    max_cycles: u64,
    stop: Option<u32>,
) -> Result<Profile, rtl::chip::RunError> {
    let mut k: BTreeMap<&str, u64> = BTreeMap::new();
    let mut c: BTreeMap<&str, u64> = BTreeMap::new();
    let mut cycles = 0u64;
    let mut was_at = stop.is_some_and(|pc| sim.top.risc.pc == pc);
    while !sim.top.halted() {
        if sim.cycle() >= max_cycles {
            return Err(rtl::chip::over_budget(sim));
        }
        if let Some(pc) = stop {
            let at = sim.top.risc.pc == pc;
            if at && !was_at {
                break;
            }
            was_at = at;
        }
        match sim.top.bcast.current() {
            Some((run, step, _)) => {
                let group = if run.mode == rtl::array::Mode::Simd {
                    1
                } else {
                    8
                };
                let a = run.ctx as u32 + group * step as u32;
                *k.entry(Names::find(&names.kernels, a)).or_default() += 1;
            }
            None => {
                *c.entry(Names::find(&names.labels, sim.top.risc.pc))
                    .or_default() += 1;
            }
        }
        cycles += 1;
        sim.step().map_err(rtl::chip::RunError::Step)?;
    }
    Ok(Profile {
        cycles,
        kernels: sorted(k),
        control: sorted(c),
    })
}
