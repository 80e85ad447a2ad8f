//! The RC interconnect: what operand A of an RC can read in one cycle.
//!
//! Every RC drives its output register `out` onto the wires below; in a
//! cycle an RC reads **one** of them through MUX A (the `asrc` field of its
//! context, with the index in `ra`). Everything it reads is the `out` value
//! of the *start* of the cycle (a register), so the order in which lanes
//! compute never matters.
//!
//! | `asrc` | `ra`       | RC (row r, column c) reads                                   |
//! |--------|------------|--------------------------------------------------------------|
//! | `n`    | 0          | north neighbour (r-1, c)                                     |
//! | `s`    | 1          | south neighbour (r+1, c)                                     |
//! | `w`    | 2          | west neighbour  (r, c-1)                                     |
//! | `e`    | 3          | east neighbour  (r, c+1)                                     |
//! | `qrowK`| K = 0..3   | horizontal short lane: (r, 4*(c/4) + K), same quadrant row   |
//! | `qcolK`| K = 0..3   | vertical short lane:   (4*(r/4) + K, c), same quadrant column|
//! | `xrowK`| K = 0..7   | horizontal express lane: (r, K), anywhere in its row         |
//! | `xcolK`| K = 0..7   | vertical express lane:   (K, c), anywhere in its column      |
//! | `fbK`  | K = 0, 1   | the frame-buffer datum broadcast this cycle by set K         |
//!
//! **Edges wrap** (the array is a torus for the neighbour links): the north
//! neighbour of row 0 is row 7, the east neighbour of column 7 is column 0.
//! Reading one's own position through a lane (`qrow` / `xrow` with K equal to
//! one's own column) returns one's own `out`.
//!
//! **Lane drivers.** A short or express lane is a bus with one driver per
//! cycle. In SIMD mode every RC of a row asks for the same index K, so each
//! bus has one driver. In row mode (each row its own context) the rows may
//! ask a vertical lane (`qcol`, `xcol`) of the same column for different
//! drivers, and in column mode the columns may do so for a horizontal lane
//! (`qrow`, `xrow`): the array refuses that with a fault ("lane conflict").
//! Neighbour links are point to point and never conflict.

use crate::rc::context::ASrc;

/// Row-major lane index of (row, column).
#[inline(always)]
pub const fn lane(row: usize, col: usize) -> usize {
    row * 8 + col
}

/// The source lane of every lane for one (`asrc`, `ra`) selection.
pub type Route = [u8; 64];

/// Routing tables: for each interconnect source and index, the lane each RC
/// reads. Built once; the array's cycle is one table lookup per RC.
pub struct Interconnect {
    /// `[kind][k]` with kind 0 Nbr (k 0..3), 1 QRow (0..3), 2 QCol (0..3),
    /// 3 XRow (0..7), 4 XCol (0..7).
    routes: [[Route; 8]; 5],
}

impl Default for Interconnect {
    fn default() -> Self {
        Self::new()
    }
}

impl Interconnect {
    pub fn new() -> Interconnect {
        let mut routes = [[[0u8; 64]; 8]; 5];
        for k in 0..8 {
            for r in 0..8 {
                for c in 0..8 {
                    let i = lane(r, c);
                    let nbr = match k & 3 {
                        0 => lane((r + 7) % 8, c),
                        1 => lane((r + 1) % 8, c),
                        2 => lane(r, (c + 7) % 8),
                        _ => lane(r, (c + 1) % 8),
                    };
                    routes[0][k][i] = nbr as u8;
                    routes[1][k][i] = lane(r, c / 4 * 4 + (k & 3)) as u8;
                    routes[2][k][i] = lane(r / 4 * 4 + (k & 3), c) as u8;
                    routes[3][k][i] = lane(r, k) as u8;
                    routes[4][k][i] = lane(k, c) as u8;
                }
            }
        }
        Interconnect { routes }
    }

    /// The routing table of an interconnect source (`None` for the sources
    /// that are not lanes: registers, own output, frame buffer).
    #[inline(always)]
    pub fn route(&self, asrc: ASrc, ra: u8) -> Option<&Route> {
        let (kind, k) = match asrc {
            ASrc::Nbr => (0, ra & 3),
            ASrc::QRow => (1, ra & 3),
            ASrc::QCol => (2, ra & 3),
            ASrc::XRow => (3, ra & 7),
            ASrc::XCol => (4, ra & 7),
            _ => return None,
        };
        Some(&self.routes[kind][k as usize])
    }

    /// Compute operand A (`ext`) of every lane for one SIMD selection.
    ///
    /// The hot path: each source is a block copy (rotations, row or column
    /// broadcasts) rather than a per-lane lookup; the tests check it against
    /// the routing tables.
    #[inline(always)]
    pub fn drive<T: Copy + Default>(
        &self,
        asrc: ASrc,
        ra: u8,
        out: &[T; 64],
        fb: [T; 2],
        ext: &mut [T; 64],
    ) {
        match asrc {
            ASrc::Fb => *ext = [fb[(ra & 1) as usize]; 64],
            ASrc::Reg | ASrc::Out => {}
            ASrc::Nbr => match ra & 3 {
                // north: row r reads row r-1 (row 0 reads row 7)
                0 => {
                    ext[8..].copy_from_slice(&out[..56]);
                    ext[..8].copy_from_slice(&out[56..]);
                }
                // south: row r reads row r+1
                1 => {
                    ext[..56].copy_from_slice(&out[8..]);
                    ext[56..].copy_from_slice(&out[..8]);
                }
                // west: column c reads column c-1
                2 => {
                    for (e, o) in ext.chunks_exact_mut(8).zip(out.chunks_exact(8)) {
                        e[1..].copy_from_slice(&o[..7]);
                        e[0] = o[7];
                    }
                }
                _ => {
                    for (e, o) in ext.chunks_exact_mut(8).zip(out.chunks_exact(8)) {
                        e[..7].copy_from_slice(&o[1..]);
                        e[7] = o[0];
                    }
                }
            },
            ASrc::XRow => {
                let k = (ra & 7) as usize;
                for (e, o) in ext.chunks_exact_mut(8).zip(out.chunks_exact(8)) {
                    e.fill(o[k]);
                }
            }
            ASrc::XCol => {
                let k = (ra & 7) as usize;
                let row: [T; 8] = out[8 * k..8 * k + 8]
                    .try_into()
                    .unwrap_or([T::default(); 8]);
                for e in ext.chunks_exact_mut(8) {
                    e.copy_from_slice(&row);
                }
            }
            ASrc::QRow => {
                let k = (ra & 3) as usize;
                for (e, o) in ext.chunks_exact_mut(8).zip(out.chunks_exact(8)) {
                    e[..4].fill(o[k]);
                    e[4..].fill(o[4 + k]);
                }
            }
            ASrc::QCol => {
                let k = (ra & 3) as usize;
                let (top, bottom) = ext.split_at_mut(32);
                for e in top.chunks_exact_mut(8) {
                    e.copy_from_slice(&out[8 * k..8 * k + 8]);
                }
                for e in bottom.chunks_exact_mut(8) {
                    e.copy_from_slice(&out[8 * (4 + k)..8 * (4 + k) + 8]);
                }
            }
        }
    }

    /// The same as [`Interconnect::drive`], by table lookup (reference).
    pub fn drive_by_table<T: Copy + Default>(
        &self,
        asrc: ASrc,
        ra: u8,
        out: &[T; 64],
        fb: [T; 2],
        ext: &mut [T; 64],
    ) {
        match self.route(asrc, ra) {
            Some(t) => {
                for i in 0..64 {
                    ext[i] = out[t[i] as usize];
                }
            }
            None => self.drive(asrc, ra, out, fb, ext),
        }
    }

    /// Compute operand A of the lanes in `lanes` only (row and column mode).
    pub fn drive_lanes<T: Copy + Default>(
        &self,
        asrc: ASrc,
        ra: u8,
        lanes: &[usize],
        out: &[T; 64],
        fb: [T; 2],
        ext: &mut [T; 64],
    ) {
        match asrc {
            ASrc::Fb => {
                for &i in lanes {
                    ext[i] = fb[(ra & 1) as usize];
                }
            }
            ASrc::Reg | ASrc::Out => {}
            _ => {
                let t = self.route(asrc, ra).expect("lane source");
                for &i in lanes {
                    ext[i] = out[t[i] as usize];
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Independent reference: what (r, c) reads, by coordinates.
    fn reference(asrc: ASrc, k: usize, r: usize, c: usize) -> (usize, usize) {
        match asrc {
            ASrc::Nbr => match k {
                0 => ((r + 7) % 8, c),
                1 => ((r + 1) % 8, c),
                2 => (r, (c + 7) % 8),
                _ => (r, (c + 1) % 8),
            },
            ASrc::QRow => (r, if c < 4 { k } else { 4 + k }),
            ASrc::QCol => (if r < 4 { k } else { 4 + k }, c),
            ASrc::XRow => (r, k),
            ASrc::XCol => (k, c),
            _ => unreachable!(),
        }
    }

    #[test]
    fn every_lane_path_reads_the_documented_rc() {
        let ic = Interconnect::new();
        // out value encodes the position: 10*row + col.
        let out: [i16; 64] = std::array::from_fn(|i| (i / 8 * 10 + i % 8) as i16);
        let cases = [
            (ASrc::Nbr, 4),
            (ASrc::QRow, 4),
            (ASrc::QCol, 4),
            (ASrc::XRow, 8),
            (ASrc::XCol, 8),
        ];
        for (asrc, n) in cases {
            for k in 0..n {
                let mut ext = [0i16; 64];
                ic.drive(asrc, k as u8, &out, [0, 0], &mut ext);
                for r in 0..8 {
                    for c in 0..8 {
                        let (sr, sc) = reference(asrc, k, r, c);
                        assert_eq!(
                            ext[r * 8 + c],
                            (sr * 10 + sc) as i16,
                            "{asrc:?} k={k} at ({r},{c})"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn block_copies_equal_the_routing_tables() {
        let ic = Interconnect::new();
        let out: [i16; 64] = std::array::from_fn(|i| (i as i16) * 7 - 100);
        for asrc in [ASrc::Nbr, ASrc::QRow, ASrc::QCol, ASrc::XRow, ASrc::XCol] {
            for k in 0..8 {
                let (mut a, mut b) = ([0i16; 64], [1i16; 64]);
                ic.drive(asrc, k, &out, [0, 0], &mut a);
                ic.drive_by_table(asrc, k, &out, [0, 0], &mut b);
                assert_eq!(a, b, "{asrc:?} {k}");
            }
        }
    }

    #[test]
    fn short_lanes_stay_inside_the_quadrant_and_express_lanes_reach_the_row() {
        let ic = Interconnect::new();
        for r in 0..8 {
            for c in 0..8 {
                let i = r * 8 + c;
                let mut row_short = std::collections::BTreeSet::new();
                let mut row_express = std::collections::BTreeSet::new();
                for k in 0..4 {
                    let s = ic.route(ASrc::QRow, k).unwrap()[i] as usize;
                    assert_eq!(s / 8, r);
                    assert_eq!(s % 8 / 4, c / 4, "short lane leaves the quadrant");
                    row_short.insert(s);
                    let s = ic.route(ASrc::QCol, k).unwrap()[i] as usize;
                    assert_eq!((s / 8 / 4, s % 8), (r / 4, c));
                }
                for k in 0..8 {
                    row_express.insert(ic.route(ASrc::XRow, k).unwrap()[i] as usize);
                }
                // 3 others + self in the quadrant row, 7 others + self in the row.
                assert_eq!(row_short.len(), 4);
                assert_eq!(row_express.len(), 8);
            }
        }
    }

    #[test]
    fn frame_buffer_sources_broadcast_one_datum_per_set() {
        let ic = Interconnect::new();
        let mut ext = [0i16; 64];
        ic.drive(ASrc::Fb, 1, &[0; 64], [11, -22], &mut ext);
        assert!(ext.iter().all(|&v| v == -22));
        ic.drive(ASrc::Fb, 0, &[0; 64], [11, -22], &mut ext);
        assert!(ext.iter().all(|&v| v == 11));
    }
}
