//! The RC flag register, lane-wise: one bit per RC in each mask.
//!
//! * `f` the guard flag, set by `CMP`; a guarded context executes only in
//!   RCs whose `f` matches its guard.
//! * `c` carry / borrow, `v` overflow or saturation (see [`super::alu`]).
//! * `sleep`: a sleeping RC executes nothing but `WAKE`.

use super::lanes::Mask;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Flags {
    pub f: Mask,
    pub c: Mask,
    pub v: Mask,
    pub sleep: Mask,
}

impl Flags {
    /// Update the lanes in `en` of `old` with `new`.
    #[inline(always)]
    pub fn merge(old: Mask, en: Mask, new: Mask) -> Mask {
        (old & !en) | (new & en)
    }

    /// [`Flags::merge`] computed another way (the same bits).
    #[inline(always)]
    pub fn merge_xor(old: Mask, en: Mask, new: Mask) -> Mask {
        old ^ ((old ^ new) & en)
    }
}
