//! A record's layout, declared once ([`Field`], [`Layout`]: the header's
//! names and offsets, the record's words and the writer's order all come
//! from it), the FB record writer every primitive writes its record with
//! ([`W`]: words in the order the kernels stream them, in the scene's
//! format and the datapath's word), and the fitter of the kernels' scale
//! shifts ([`Fitter`]).

use crate::scene::Vec3;
use crate::scene_image::{Q_MATERIAL, Q_UNIT};

use super::super::math::word_max;

/// A field of an FB record: its name and what it holds. A field the
/// TinyRISC code addresses is `named` (upper case): the program's header
/// defines it as its offset from the record's start (`CYL_BODY = 1 ;
/// cylinder record: the body's stream`); the others name a part of the
/// stream for the reader and the writer's check.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Field {
    pub name: &'static str,
    pub what: &'static str,
    pub named: bool,
}

impl Field {
    /// A field the header names.
    pub const fn named(name: &'static str, what: &'static str) -> Field {
        Field {
            name,
            what,
            named: true,
        }
    }

    /// A part of the stream the header does not name.
    pub const fn part(name: &'static str, what: &'static str) -> Field {
        Field {
            name,
            what,
            named: false,
        }
    }
}

impl std::fmt::Display for Field {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name)
    }
}

/// One record's layout: its fields in stream order, each with its words.
/// The record's words, the header's offsets and the check of the writer
/// ([`W::field`]) and of the kernels' FB reads come from it.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Layout(pub Vec<(Field, usize)>);

/// Words of `fields` (a record's const field list).
pub const fn total(fields: &[(Field, usize)]) -> usize {
    let mut n = 0;
    let mut i = 0;
    while i < fields.len() {
        n += fields[i].1;
        i += 1;
    }
    n
}

impl Layout {
    /// The fields in order.
    pub fn new(fields: impl IntoIterator<Item = (Field, usize)>) -> Layout {
        Layout(fields.into_iter().collect())
    }

    /// Words of the record.
    pub fn words(&self) -> usize {
        self.0.iter().map(|f| f.1).sum()
    }

    /// The offset of `field` from the record's start, if the record has it.
    pub fn offset(&self, field: Field) -> Option<usize> {
        let mut at = 0;
        for &(f, n) in &self.0 {
            if f == field {
                return Some(at);
            }
            at += n;
        }
        None
    }

    /// Words of `field`, if the record has it.
    pub fn words_of(&self, field: Field) -> Option<usize> {
        self.0.iter().find(|f| f.0 == field).map(|f| f.1)
    }

    /// The header lines of the named fields of `layouts` (a primitive's
    /// records of each side the scene has), each name once, in the order
    /// the layouts list them; a name at two offsets is a bug of the
    /// layouts.
    pub fn header(layouts: &[Layout]) -> Vec<String> {
        let mut seen: Vec<(Field, usize)> = Vec::new();
        for l in layouts {
            for &(f, _) in l.0.iter().filter(|f| f.0.named) {
                let at = l.offset(f).unwrap_or(0);
                match seen.iter().find(|s| s.0 == f) {
                    Some(s) => debug_assert_eq!(s.1, at, "{} at two offsets", f.name),
                    None => seen.push((f, at)),
                }
            }
        }
        seen.iter()
            .map(|(f, at)| super::super::emit::define(f.name, *at, f.what))
            .collect()
    }
}

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
    /// Where the writer began each field it marked ([`W::field`]), for
    /// the check against the record's [`Layout`].
    pub(crate) marks: Vec<(Field, usize)>,
}

impl W {
    /// An empty FB image of `s` LSBs per scene unit (`frac` fraction bits;
    /// `x` the datapath's extra bits).
    pub fn new(s: f64, frac: u32, x: u32) -> W {
        W {
            fb: Vec::new(),
            s,
            frac,
            x,
            fans: Vec::new(),
            fan_most: 0,
            marks: Vec::new(),
        }
    }

    /// Mark the start of `field` (the next word written), for the check
    /// of the writer's order against the record's [`Layout`].
    /// (Kept in the unit tests' builds only.)
    pub fn field(&mut self, field: Field) {
        if cfg!(test) {
            self.marks.push((field, self.fb.len()));
        }
    }

    /// Drop the words from `len` on, and the marks there.
    pub fn truncate(&mut self, len: usize) {
        self.fb.truncate(len);
        self.marks.retain(|m| m.1 < len);
    }

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
