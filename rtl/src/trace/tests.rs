//! The waveform writers against hand-made signals and files.

use super::files::glob;
use super::format::{bin8, binary, binary_portable, Clock, VcdBody, DECIMAL_LIMIT, VCD_CHUNK};
use super::handoff::{
    copy_streaming, Handoff, WriterGone, BATCH, IDLE_POLLS, MSG_CHUNK, POLL, QUEUED_BATCHES,
};
use super::tracer::Chunk;
use super::{Display, Field, LabelKind, Labels, Probe, TraceConfig, Traced};
use crate::kernel::{Clocked, Fault, Sim};

#[test]
fn labels_name_an_address_by_the_label_at_or_before_it() {
    let l = Labels {
        code: vec![(8, "loop".into()), (20, "done".into())],
        context: vec![(0, "k_a".into())],
    };
    assert_eq!(l.locate(LabelKind::Code, 4), None);
    assert_eq!(l.locate(LabelKind::Code, 8).as_deref(), Some("loop"));
    assert_eq!(l.locate(LabelKind::Code, 16).as_deref(), Some("loop+8"));
    assert_eq!(l.locate(LabelKind::Code, 24).as_deref(), Some("done+4"));
    assert_eq!(l.locate(LabelKind::Context, 3).as_deref(), Some("k_a+3"));
}

use std::path::Path;

/// A counter reporting the same signals through blocks (of values
/// given and filled in, and versioned ones) or through one call per
/// scope and signal.
struct Demo {
    t: u64,
    by_block: bool,
}

impl Clocked for Demo {
    fn eval(&mut self) -> Result<(), Fault> {
        Ok(())
    }
    fn commit(&mut self) {
        self.t += 1;
    }
}

impl Traced for Demo {
    fn trace<P: Probe>(&self, p: &mut P) {
        let t = self.t;
        let (a, b, c, d) = (t, t / 3, (t * 7) as i16 as u64, t % 2);
        let (r0, r1) = (t / 5, t / 5 * 3);
        let (e, f) = (t / 2 % 16, t / 2 % 4);
        if self.by_block {
            p.block_with(
                &|| {
                    vec![
                        Field::new("", "a", 8, Display::Hex),
                        Field::new("x", "b", 4, Display::Hex),
                        Field::new("x", "c", 16, Display::Signed),
                        Field::new("y", "d", 1, Display::Bin),
                    ]
                },
                |v| *v = [a, b, c, d],
            );
            // The registers change every fifth cycle, and two nested
            // sections say so; `e` every second.
            if p.section(t % 5 != 0) {
                if p.section(t % 5 != 0) {
                    p.block_versioned(
                        t / 5,
                        &|| {
                            vec![
                                Field::new("regs", "r0", 8, Display::Hex),
                                Field::new("regs", "r1", 8, Display::Hex),
                            ]
                        },
                        &mut |v| {
                            v[0] = r0;
                            v[1] = r1;
                        },
                    );
                    p.end_section();
                }
                p.end_section();
            }
            if p.section(t % 2 == 1) {
                p.block_versioned(
                    t / 2,
                    &|| vec![Field::new("w", "e", 4, Display::Hex)],
                    &mut |v| v[0] = e,
                );
                p.block_with(&|| vec![Field::new("v", "f", 2, Display::Hex)], |v| {
                    *v = [f]
                });
                p.end_section();
            }
            p.block(&|| vec![Field::new("u", "g", 1, Display::Bin)], &[d]);
        } else {
            p.signal("a", 8, Display::Hex, a);
            if p.scope(format_args!("x")) {
                p.signal("b", 4, Display::Hex, b);
                p.signal("c", 16, Display::Signed, c);
                p.end();
            }
            if p.scope(format_args!("y")) {
                p.signal("d", 1, Display::Bin, d);
                p.end();
            }
            if p.section(t % 5 != 0) {
                if p.scope(format_args!("regs")) {
                    p.signal_row(&["r0", "r1"], 8, Display::Hex, &[r0, r1]);
                    p.end();
                }
                p.end_section();
            }
            if p.section(t % 2 == 1) {
                if p.scope(format_args!("w")) {
                    p.signal("e", 4, Display::Hex, e);
                    p.end();
                }
                if p.scope(format_args!("v")) {
                    if p.traced_signals(&["f"]) & 1 != 0 {
                        p.signal("f", 2, Display::Hex, f);
                    }
                    p.end();
                }
                p.end_section();
            }
            if p.scope(format_args!("u")) {
                if p.traced_signals(&["g"]) & 1 != 0 {
                    p.signal("g", 1, Display::Bin, d);
                }
                p.end();
            }
        }
    }
}

fn waveform(dir: &Path, by_block: bool, scope: &str, first: u64) -> Vec<u8> {
    let path = dir.join(format!("{by_block}.vcd"));
    let mut cfg = TraceConfig::new(&path);
    cfg.scope = scope.into();
    cfg.first = first;
    let mut sim = Sim::new(Demo { t: 0, by_block });
    sim.trace(cfg, "demo").unwrap();
    for _ in 0..600 {
        sim.step().unwrap();
    }
    sim.finish_trace().unwrap();
    std::fs::read(&path).unwrap()
}

/// Blocks and versioned blocks write the waveform that one call per
/// scope and signal writes, whatever the scope filter and window; and
/// so do sections skipped while unchanged (the registers' scope, and
/// their versioned block within two nested sections).
#[test]
fn blocks_write_what_single_calls_write() {
    let dir = tempfile::tempdir().unwrap();
    for (scope, first) in [
        ("", 0),
        ("x,regs", 0),
        ("y", 7),
        ("regs.r1,a", 13),
        ("regs", 3),
        ("regs,w", 0),
        ("v.f,x", 5),
        ("v,u.x", 4),
    ] {
        let calls = waveform(dir.path(), false, scope, first);
        let blocks = waveform(dir.path(), true, scope, first);
        assert!(calls.len() > 2000, "{scope}: {} bytes", calls.len());
        assert!(
            calls == blocks,
            "{scope} from {first}: the waveforms differ"
        );
    }
}

/// A tracer dropped without being finished (a run that failed) ends
/// its writing thread and leaves no file.
#[test]
fn an_unfinished_waveform_ends_its_writer_and_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cut.vcd");
    let p = path.clone();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let mut sim = Sim::new(Demo {
            t: 0,
            by_block: true,
        });
        sim.trace(TraceConfig::new(&p), "demo").unwrap();
        for _ in 0..40_000 {
            sim.step().unwrap();
        }
        drop(sim);
        tx.send(()).unwrap();
    });
    rx.recv_timeout(std::time::Duration::from_secs(20))
        .expect("dropping the tracer waited for its writer for ever");
    assert!(!path.exists());
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert!(left.is_empty(), "{left:?}");
}

/// A waveform of some megabytes is written to blocks allocated ahead
/// of it, and the file keeps none of them past its end: its length is
/// its content (it ends with the last falling edge and the time the
/// trace ends at) and it occupies no more than that.
#[test]
fn a_long_waveform_keeps_no_blocks_past_its_end() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("long.vcd");
    let mut sim = Sim::new(Demo {
        t: 0,
        by_block: true,
    });
    sim.trace(TraceConfig::new(&path), "demo").unwrap();
    let cycles = 60_000;
    for _ in 0..cycles {
        sim.step().unwrap();
    }
    sim.finish_trace().unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.len() > 3 << 20, "{} bytes", text.len());
    let end = Clock::new(TraceConfig::new("x").clock_hz).time(cycles);
    assert!(
        text.ends_with(&format!("\n0!\n#{end}\n")),
        "ends with {:?}",
        &text[text.len() - 40..]
    );
    #[cfg(target_os = "linux")]
    {
        use std::os::unix::fs::MetadataExt;
        let m = std::fs::metadata(&path).unwrap();
        assert_eq!(m.len(), text.len() as u64);
        assert!(
            m.blocks() * 512 < m.len() + (64 << 10),
            "{} bytes in {} blocks of 512",
            m.len(),
            m.blocks()
        );
    }
}

/// A xorshift generator of test values from `seed`.
fn xorshift(mut x: u64) -> impl FnMut() -> u64 {
    move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    }
}

/// A batch handed over is a copy of every word, whatever its length
/// and wherever the copy starts against a cache line.
#[test]
fn streaming_copies_hold_every_word() {
    let mut next = xorshift(0x0F1E_2D3C_4B5A_6978);
    for len in (0..200).chain([4095, 4096, 4097, BATCH + 77]) {
        let src: Vec<u64> = (0..len).map(|_| next()).collect();
        for skew in 0..9 {
            let mut dst: Vec<u64> = (0..skew).map(|_| next()).collect();
            let mut want = dst.clone();
            want.extend_from_slice(&src);
            copy_streaming(&mut dst, &src);
            assert!(dst == want, "{len} words after {skew}");
        }
    }
}

/// Batches handed over arrive whole and in order, whether the writing
/// thread polls for them, has fallen asleep (long gaps: the first
/// batch after one wakes it) or is behind (a full queue); a writing
/// thread that ends stops the sender instead of leaving it waiting.
#[test]
fn handed_over_batches_arrive_in_order() {
    use std::sync::Arc;
    use std::time::Duration;
    let q = Arc::new(Handoff::new());
    let rx = WriterGone(q.clone());
    let (ack, acks) = std::sync::mpsc::channel();
    let reader = std::thread::spawn(move || {
        let mut got = Vec::new();
        while let Some(b) = rx.0.recv() {
            if got.len() % 50 < 20 {
                // Behind: the queue fills.
                std::thread::sleep(Duration::from_micros(200));
            }
            got.push(b.clone());
            rx.0.give_back(b);
            let _ = ack.send(got.len());
        }
        got
    });
    let mut sent = Vec::new();
    for k in 0..300u64 {
        let mut b = q.empty.lock().unwrap().pop().unwrap_or_default();
        assert!(b.is_empty());
        b.extend((0..k % 7).map(|i| k << 8 | i));
        sent.push(b.clone());
        assert!(q.send(b, reader.thread()));
        if k % 60 == 0 && k > 0 {
            // The batch after the sleep woke the reader (it would
            // otherwise sleep until the queue is full).
            while acks.recv_timeout(Duration::from_secs(10)).expect("woken") <= k as usize {}
        }
        if k % 60 == 59 {
            // Long enough for the reader to fall asleep.
            std::thread::sleep(POLL * IDLE_POLLS * 20);
        }
    }
    q.done.store(true, std::sync::atomic::Ordering::SeqCst);
    reader.thread().unpark();
    assert!(reader.join().unwrap() == sent);

    // A reader that takes two batches and ends.
    let q = Arc::new(Handoff::new());
    let rx = WriterGone(q.clone());
    let reader = std::thread::spawn(move || {
        rx.0.recv();
        rx.0.recv();
    });
    let thread = reader.thread().clone();
    let mut sent = 0;
    while q.send(vec![1], &thread) {
        sent += 1;
        assert!(sent < 100_000, "the sender never saw the reader gone");
    }
    reader.join().unwrap();
    assert!((2..=2 + QUEUED_BATCHES).contains(&sent), "{sent} sent");
}

/// Timestamps are written as `core::fmt` writes them: times growing
/// by the half periods of several clocks (across digit counts and
/// 10^16), by larger steps, and times out of order.
#[test]
fn timestamps_are_formatted_as_core_fmt_formats_them() {
    let mut next = xorshift(0x2545_F491_4F6C_DD1D);
    let mut runs: Vec<Vec<u64>> = Vec::new();
    for hz in [300_000_000u64, 1_000_000_000_000, 7, 123_456_789] {
        for start in [0u64, 99_990_000, 999_999_999_999_000, 9_999_999_999_990_000] {
            let mut clock = Clock::new(hz);
            let c0 = (start as u128 * hz as u128 / 1_000_000_000_000) as u64;
            let mut ts = Vec::new();
            for c in c0..c0 + 3000 {
                let (rise, fall) = clock.edges(c);
                ts.extend([rise, fall]);
            }
            runs.push(ts);
        }
    }
    let mut t = 0u64;
    runs.push(
        (0..3000)
            .map(|_| {
                t += next() % 1_000_000_000;
                t
            })
            .collect(),
    );
    runs.push((0..3000).map(|_| next() >> (next() % 64)).collect());
    runs.push(vec![
        0,
        0,
        1,
        9,
        10,
        99,
        100,
        u64::MAX,
        5,
        DECIMAL_LIMIT - 1,
        DECIMAL_LIMIT,
        3,
    ]);
    for (r, times) in runs.iter().enumerate() {
        let mut body = VcdBody::new(false);
        let mut want = String::new();
        for (k, &t) in times.iter().enumerate() {
            body.timestamp(t);
            want.push_str(&format!("#{t}\n"));
            if body.len > VCD_CHUNK || k + 1 == times.len() {
                let got = std::str::from_utf8(&body.buf[..body.len]).unwrap();
                assert!(got == want, "run {r}, up to time {k}");
                body.len = 0;
                want.clear();
            }
        }
    }
}

/// Binary digits are the same whichever way they are made (with
/// AVX-512 where the build has it) and are `core::fmt`'s.
#[test]
fn binary_digits_are_core_fmt_binary_digits() {
    let mut next = xorshift(0x0123_4567_89AB_CDEF);
    for round in 0..20_000 {
        let x = next();
        let v = if round < 128 {
            (1u64 << (round % 64)) - (round / 64)
        } else {
            x >> (x % 64)
        };
        let bits = 64 - (v | 1).leading_zeros() as usize;
        let (mut fast, mut slow) = ([b'x'; 64], [b'y'; 64]);
        binary(&mut fast, v, bits);
        binary_portable(&mut slow, v, bits);
        let want = format!("{v:b}");
        assert_eq!(&fast[..bits], want.as_bytes(), "{v:#x}");
        assert_eq!(&slow[..bits], want.as_bytes(), "{v:#x}");
    }
}

/// A chunk's change message is the same whichever way it is built
/// (with AVX-512 where the build has it, over the groups that hold
/// declared calls; one change at a time otherwise) and says what
/// changed: every traced call whose value, cut to its width, differs
/// from the last one written, in order, with the bytes their changes
/// add.
#[test]
fn chunk_messages_hold_the_changed_values_in_order() {
    let mut next = xorshift(0x9E37_79B9_7F4A_7C15);
    for round in 0..2000 {
        let (mut c, mut m, mut l, mut cost) = ([0u64; 64], [0u64; 64], [0u64; 64], [0u8; 64]);
        let density = next() % 65;
        // Calls past the chunk's last group of declared ones are
        // padding (not traced).
        let groups = 1 + (next() % 8) as usize;
        for k in 0..64 {
            let width = if k < 8 * groups { next() % 65 } else { 0 };
            m[k] = if width == 0 {
                0
            } else {
                u64::MAX >> (64 - width)
            };
            cost[k] = m[k].count_ones() as u8 + 6;
            l[k] = next() & m[k];
            // Some calls keep their value; some change only above
            // their width (no change).
            c[k] = match next() % 64 {
                r if r < density => next(),
                r if r % 2 == 0 => l[k] | !m[k] & next(),
                _ => l[k],
            };
        }
        let first = round % 7 == 0;
        let j = next() % 5;
        let (mut fast, mut slow) = (vec![7u64], vec![7u64]);
        fast.reserve(80);
        let (mut lf, mut ls) = (l, l);
        let bf = Chunk {
            c: &c,
            m: &m,
            l: &mut lf,
            cost: &cost,
        }
        .changes(&mut fast, j, first, groups);
        let bs = Chunk {
            c: &c,
            m: &m,
            l: &mut ls,
            cost: &cost,
        }
        .changes_portable(&mut slow, j, first);
        assert_eq!((&fast, bf, lf), (&slow, bs, ls), "round {round}");
        // What the message should say, computed plainly.
        let changed: Vec<usize> = (0..64)
            .filter(|&k| m[k] != 0 && (first || c[k] & m[k] != l[k]))
            .collect();
        let mut want = vec![7u64];
        if !changed.is_empty() {
            want.push(MSG_CHUNK << 48 | j);
            want.push(changed.iter().map(|&k| 1u64 << k).sum());
            want.extend(changed.iter().map(|&k| c[k] & m[k]));
        }
        assert_eq!(slow, want, "round {round}");
        let bytes: u64 = changed.iter().map(|&k| u64::from(cost[k])).sum();
        assert_eq!(bs, bytes, "round {round}");
        for k in 0..64 {
            let kept = if changed.contains(&k) {
                c[k] & m[k]
            } else {
                l[k]
            };
            assert_eq!(ls[k], kept, "round {round}, call {k}");
        }
    }
}

/// A value change is written as `core::fmt` writes it: `b`, the
/// binary digits without leading zeros, a space and the code (one
/// digit and the code for one bit).
#[test]
fn value_changes_are_formatted_as_core_fmt_formats_them() {
    let mut body = VcdBody::new(false);
    body.add_id("!").unwrap();
    body.add_id("%a~").unwrap();
    let mut values: Vec<u64> = vec![0, 1, 2, 3, 0xFF, 0x100, 0x8000, u64::MAX, 1 << 63];
    let mut x = 0x9E37_79B9_7F4A_7C15u64;
    for _ in 0..2000 {
        // xorshift, with every width of value
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        values.push(x >> (x % 64));
    }
    let mut want = String::new();
    for (k, &v) in values.iter().enumerate() {
        let (id, code) = if k % 2 == 0 { (0, "!") } else { (1, "%a~") };
        body.change(id, 64, v);
        want.push_str(&format!("b{v:b} {code}\n"));
        body.change(id, 1, v);
        want.push_str(&format!("{}{code}\n", v & 1));
        if body.len > VCD_CHUNK / 2 {
            break;
        }
    }
    assert_eq!(std::str::from_utf8(&body.buf[..body.len]).unwrap(), want);
    // Timestamps: every number of digits, and the edges of each.
    let mut body = VcdBody::new(false);
    let mut want = String::new();
    let mut times = vec![0, 1, 9, 10, 99, 100, 999, u64::MAX, u64::MAX - 1];
    for d in 1..20 {
        let p = 10u64.pow(d);
        times.extend([p - 1, p, p + 1, p + p / 3]);
    }
    for _ in 0..2000 {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        times.push(x >> (x % 64));
    }
    for t in times {
        body.timestamp(t);
        want.push_str(&format!("#{t}\n"));
    }
    assert_eq!(std::str::from_utf8(&body.buf[..body.len]).unwrap(), want);
    for b in 0..=255u8 {
        assert_eq!(bin8(b).to_le_bytes(), *format!("{b:08b}").as_bytes());
    }
}

#[test]
fn glob_matches_like_a_shell() {
    assert!(glob("rc_r*_c0", "rc_r3_c0"));
    assert!(!glob("rc_r*_c0", "rc_r3_c1"));
    assert!(glob("r?", "r3"));
    assert!(!glob("r?", "r13"));
    assert!(glob("*", "anything"));
    assert!(glob("alu", "alu"));
    assert!(!glob("alu", "alux"));
}
