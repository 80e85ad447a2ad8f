//! The instruction set the per-cycle path runs on, chosen at run time.
//!
//! The binary is built for the target's baseline (x86-64, aarch64, ...),
//! so it runs on any CPU of its architecture. The functions of the
//! per-cycle path that gain from wide vectors (the 64 lanes' evaluation,
//! the cycle loops) are compiled once per [`Simd`] path by [`versions!`],
//! and each call takes the path [`level`] names: the widest the CPU has,
//! or the one `MORPHOSYS_SIMD=portable|avx2|avx512` forces. The paths
//! compute the same integers (the lanes are integer arithmetic, and no
//! floating point is contracted), so cycles, states, images and
//! waveforms are the same on every path (`tb/tests/simd.rs`).

use std::sync::atomic::{AtomicU8, Ordering};

/// An instruction set the per-cycle path is compiled for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Simd {
    /// The target's baseline (SSE2 on x86-64, NEON on aarch64).
    Portable,
    /// x86-64-v3: AVX2, BMI1/2, FMA, LZCNT, MOVBE, POPCNT.
    Avx2,
    /// x86-64-v4: AVX2 and AVX-512 F, BW, CD, DQ, VL.
    Avx512,
}

/// The variable that forces a path.
pub const ENV: &str = "MORPHOSYS_SIMD";

impl Simd {
    /// Every path, narrowest first.
    pub const ALL: [Simd; 3] = [Simd::Portable, Simd::Avx2, Simd::Avx512];

    /// The name `MORPHOSYS_SIMD` takes and `bench` prints.
    pub fn name(self) -> &'static str {
        match self {
            Simd::Portable => "portable",
            Simd::Avx2 => "avx2",
            Simd::Avx512 => "avx512",
        }
    }

    /// Whether this CPU can run the path.
    pub fn supported(self) -> bool {
        match self {
            Simd::Portable => true,
            #[cfg(target_arch = "x86_64")]
            Simd::Avx2 => {
                std::arch::is_x86_feature_detected!("avx2")
                    && std::arch::is_x86_feature_detected!("bmi1")
                    && std::arch::is_x86_feature_detected!("bmi2")
                    && std::arch::is_x86_feature_detected!("fma")
                    && std::arch::is_x86_feature_detected!("lzcnt")
                    && std::arch::is_x86_feature_detected!("movbe")
                    && std::arch::is_x86_feature_detected!("popcnt")
            }
            #[cfg(target_arch = "x86_64")]
            Simd::Avx512 => {
                Simd::Avx2.supported()
                    && std::arch::is_x86_feature_detected!("avx512f")
                    && std::arch::is_x86_feature_detected!("avx512bw")
                    && std::arch::is_x86_feature_detected!("avx512cd")
                    && std::arch::is_x86_feature_detected!("avx512dq")
                    && std::arch::is_x86_feature_detected!("avx512vl")
            }
            #[cfg(not(target_arch = "x86_64"))]
            _ => false,
        }
    }

    /// The widest path this CPU can run.
    pub fn best() -> Simd {
        Simd::ALL
            .into_iter()
            .rev()
            .find(|s| s.supported())
            .unwrap_or(Simd::Portable)
    }

    /// The path `MORPHOSYS_SIMD` names (unset or empty: [`Simd::best`]); an
    /// unknown name or a path this CPU lacks is an error naming the
    /// variable.
    pub fn from_env() -> Result<Simd, String> {
        match std::env::var(ENV) {
            Err(std::env::VarError::NotPresent) => Ok(Simd::best()),
            Err(std::env::VarError::NotUnicode(v)) => {
                Err(format!("{ENV}={v:?}: expected portable, avx2 or avx512"))
            }
            Ok(v) if v.is_empty() => Ok(Simd::best()),
            Ok(v) => {
                let Some(s) = Simd::ALL.into_iter().find(|s| s.name() == v) else {
                    return Err(format!("{ENV}={v:?}: expected portable, avx2 or avx512"));
                };
                if !s.supported() {
                    return Err(format!(
                        "{ENV}={v}: this CPU cannot run the {v} path (it has {})",
                        Simd::best().name()
                    ));
                }
                Ok(s)
            }
        }
    }
}

/// 0: not chosen yet; else 1 + the path's index in [`Simd::ALL`].
static LEVEL: AtomicU8 = AtomicU8::new(0);

/// The path the per-cycle path takes: the one [`set`] chose, else the one
/// `MORPHOSYS_SIMD` names, else the widest this CPU has. (The command
/// checks the variable before any work and stops with its error; a
/// library user whose variable is wrong gets the panic's message.)
#[inline(always)]
pub fn level() -> Simd {
    match LEVEL.load(Ordering::Relaxed) {
        1 => Simd::Portable,
        2 => Simd::Avx2,
        3 => Simd::Avx512,
        _ => choose(),
    }
}

/// Whether the AVX-512 path runs: code with AVX-512 intrinsics of its own
/// (sign masks, the waveform's change packing) takes them where this
/// holds, and they are inlined into the `avx512` versions. Always true in
/// a build for a CPU with AVX-512 (`-C target-cpu=native` on one).
#[inline(always)]
pub fn avx512() -> bool {
    #[cfg(all(target_arch = "x86_64", target_feature = "avx512bw"))]
    return true;
    // The path's number alone, inlined into every caller (no call to
    // choose it: the versions' dispatch, through `level`, has chosen it
    // before any of them runs; unchosen reads as not AVX-512).
    #[cfg(all(target_arch = "x86_64", not(target_feature = "avx512bw")))]
    return LEVEL.load(Ordering::Relaxed) == 3;
    #[cfg(not(target_arch = "x86_64"))]
    return false;
}

#[cold]
#[inline(never)]
fn choose() -> Simd {
    let s = Simd::from_env().unwrap_or_else(|e| panic!("{e}"));
    set(s).unwrap_or_else(|e| panic!("{e}"));
    s
}

/// Take `simd` from now on (every thread). Refused for a path this CPU
/// cannot run.
pub fn set(simd: Simd) -> Result<(), String> {
    if !simd.supported() {
        return Err(format!(
            "this CPU cannot run the {} path (it has {})",
            simd.name(),
            Simd::best().name()
        ));
    }
    let i = Simd::ALL.iter().position(|&s| s == simd).unwrap_or(0);
    LEVEL.store(i as u8 + 1, Ordering::Relaxed);
    Ok(())
}

/// Defines a function compiled once per [`Simd`] path: the three named
/// versions (out of line, each built for its instruction set) and the
/// named function itself, which calls the version [`level`] gives.
///
/// ```text
/// crate::simd::versions! {
///     /// Doc.
///     pub fn step(&mut self) -> Result<(), Fault>;
///     versions step_portable step_avx2 step_avx512;
///     { self.exec::<true>() }
/// }
/// ```
///
/// Callees the compiler inlines into a version take its instruction set;
/// out-of-line callees keep theirs (those of the per-cycle path are
/// versions themselves).
macro_rules! versions {
    // A method taking `&mut self`.
    (
        $(#[$attr:meta])*
        $vis:vis fn $name:ident(&mut $self:ident $(, $arg:ident: $ty:ty)* $(,)?) -> $ret:ty;
        versions $portable:ident $avx2:ident $avx512:ident;
        $body:block
    ) => {
        $(#[$attr])*
        #[inline(always)]
        $vis fn $name(&mut $self $(, $arg: $ty)*) -> $ret {
            match $crate::simd::level() {
                // SAFETY: `level` gives a path only when the CPU has its
                // instruction set (`Simd::supported`).
                #[cfg(target_arch = "x86_64")]
                $crate::simd::Simd::Avx512 => unsafe { $self.$avx512($($arg),*) },
                #[cfg(target_arch = "x86_64")]
                $crate::simd::Simd::Avx2 => unsafe { $self.$avx2($($arg),*) },
                _ => $self.$portable($($arg),*),
            }
        }
        $crate::simd::versions!(@bodies [&mut $self $(, $arg: $ty)*] -> $ret;
            $portable $avx2 $avx512; $body);
    };
    // A free function.
    (
        $(#[$attr:meta])*
        $vis:vis fn $name:ident($($arg:ident: $ty:ty),* $(,)?) -> $ret:ty;
        versions $portable:ident $avx2:ident $avx512:ident;
        $body:block
    ) => {
        $(#[$attr])*
        #[inline(always)]
        $vis fn $name($($arg: $ty),*) -> $ret {
            match $crate::simd::level() {
                // SAFETY: as above.
                #[cfg(target_arch = "x86_64")]
                $crate::simd::Simd::Avx512 => unsafe { $avx512($($arg),*) },
                #[cfg(target_arch = "x86_64")]
                $crate::simd::Simd::Avx2 => unsafe { $avx2($($arg),*) },
                _ => $portable($($arg),*),
            }
        }
        $crate::simd::versions!(@bodies [$($arg: $ty),*] -> $ret;
            $portable $avx2 $avx512; $body);
    };
    // The three versions of one body, each out of line.
    (@bodies [$($params:tt)*] -> $ret:ty; $portable:ident $avx2:ident $avx512:ident; $body:block) => {
        #[inline(never)]
        fn $portable($($params)*) -> $ret $body

        #[cfg(target_arch = "x86_64")]
        #[inline(never)]
        #[target_feature(enable = "avx2,bmi1,bmi2,fma,lzcnt,movbe,popcnt")]
        fn $avx2($($params)*) -> $ret $body

        #[cfg(target_arch = "x86_64")]
        #[inline(never)]
        #[target_feature(
            enable = "avx2,bmi1,bmi2,fma,lzcnt,movbe,popcnt,avx512f,avx512bw,avx512cd,avx512dq,avx512vl"
        )]
        fn $avx512($($params)*) -> $ret $body
    };
}
pub(crate) use versions;
