//! The FB record writer every primitive writes its record with ([`W`]:
//! words in the order the kernels stream them, in the scene's format and
//! the datapath's word), and the fitter of the kernels' scale shifts
//! ([`Fitter`]).

use crate::scene::Vec3;
use crate::scene_image::{Q_MATERIAL, Q_UNIT};

use super::super::math::word_max;

/// The FB image as it is written: words (16-bit values, or 32-bit on the
/// 32-bit chip) in the order the kernels stream them.
pub struct W {
    pub(crate) fb: Vec<i32>,
    /// LSBs per scene unit (`2^frac`).
    pub(crate) s: f64,
    /// Fraction bits of the scene format.
    pub(crate) frac: u32,
    /// Extra bits of the datapath (0 or 16).
    pub(crate) x: u32,
    /// Words that live in main memory only (streamed layouts): the banded
    /// polygons' sub-edges ([`polygon::Form::Apart`]).
    pub(crate) fans: Vec<i32>,
    /// The most words of one polygon's sub-edges in `fans`.
    pub(crate) fan_most: usize,
}

impl W {
    /// Bytes of an FB word: 2 (16-bit chip) or 4.
    pub fn word_bytes(&self) -> usize {
        if self.x == 0 {
            2
        } else {
            4
        }
    }
    pub fn max(&self) -> f64 {
        word_max(self.x)
    }
    /// Round and saturate to the word.
    pub fn sat(&self, v: f64) -> i32 {
        v.round().clamp(-self.max() - 1.0, self.max()) as i32
    }
    pub fn push(&mut self, v: f64) {
        let v = self.sat(v);
        self.fb.push(v);
    }
    /// A 16-bit structural word (flags, bit vectors), sign-extended.
    pub fn word16(&mut self, v: u16) {
        self.fb.push(v as i16 as i32);
    }
    /// One in Q1.14 (16-bit chip) or Q1.30.
    pub fn one(&self) -> f64 {
        ((14 + self.x) as f64).exp2()
    }
    pub fn coord(&mut self, x: f64) {
        self.push(x * self.s);
    }
    pub fn point(&mut self, v: Vec3) {
        for x in v.to_array() {
            self.coord(x);
        }
    }
    pub fn unit(&mut self, v: Vec3) {
        let k = Q_UNIT.lsb().recip() * (self.x as f64).exp2();
        for x in v.to_array() {
            self.push(x * k);
        }
    }
    /// One component of a unit vector (Q1.14).
    pub fn unit_axis(&mut self, x: f64) {
        self.push(x * Q_UNIT.lsb().recip() * (self.x as f64).exp2());
    }
    pub fn col(&mut self, x: f64) {
        self.push(x * Q_MATERIAL.lsb().recip() * (self.x as f64).exp2());
    }
    pub fn raw(&mut self, x: i64) {
        self.push(x as f64);
    }
    pub fn scaled(&mut self, v: Vec3, scale: f64) {
        for x in v.to_array() {
            self.push(x * scale);
        }
    }
}

/// FB words as the bytes DMA moves: 2 per word (16-bit chip, `x` = 0) or
/// 4 (32-bit chip), little-endian.
pub fn fb_word_bytes(words: &[i32], x: u32) -> Vec<u8> {
    if x == 0 {
        words
            .iter()
            .flat_map(|w| (*w as i16).to_le_bytes())
            .collect()
    } else {
        words.iter().flat_map(|w| w.to_le_bytes()).collect()
    }
}

/// The scale shifts of the kernels, fitted to the word of the datapath.
pub struct Fitter {
    /// Extra bits of the datapath (0 or 16).
    pub(crate) x: u32,
}

impl Fitter {
    /// Largest shift `k` with `m * 2^k` within the word, clamped to 0..=max.
    pub fn shift(&self, m: f64, max: u32) -> u32 {
        fit_shift_w(m, max, self.x)
    }
    /// `KS` of a kernel whose record holds `2^(14+KS) / v` for the smallest
    /// `v` (LSB) of the scene: as large as keeps it in the word, at most 16
    /// (plus the datapath's extra bits); 8 where there is none.
    pub fn ks(&self, min: f64) -> u32 {
        if min.is_finite() {
            self.shift(((14 + self.x) as f64).exp2() / min, 16 + self.x)
        } else {
            8
        }
    }
}

/// Largest shift `k` with `m * 2^k` within the word (`<= 2^(15+x) - 1`:
/// 32767 on the 16-bit chip), clamped to 0..=max.
pub(crate) fn fit_shift_w(m: f64, max: u32, x: u32) -> u32 {
    if m <= 0.0 {
        return max;
    }
    let k = (word_max(x) / m).log2().floor();
    k.clamp(0.0, max as f64) as u32
}
