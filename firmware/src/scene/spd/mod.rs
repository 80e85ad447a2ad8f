//! Eric Haines' Standard Procedural Databases (SPD) generators, ported to
//! Rust from the SPD 3.x C sources (public domain / CC0).
//!
//! Each generator writes the NFF text that the C program prints with NFF
//! output (`-r 1`) and true curved primitives (`-c`): the same entities in
//! the same order, every number formatted as C's `%g` (6 significant
//! digits). The arithmetic follows the C code operation by operation (the
//! same matrix library, the same transform stack, the same random number
//! generator for `mount`), so the text is identical to the C program's
//! output; the tests check this against the bundled `scenes/spd/*.nff`
//! files that the C programs printed.
//!
//! [`scene`] parses the generated text with the NFF reader, so a generated
//! scene and the file written from it are the same [`Scene`].
//!
//! Ported: balls, gears, jacks, lattice, mount, rings, shells, tetra, tree.
//! Not ported: sombrero and teapot (both are tessellated into `pp` patches
//! by the SPD itself) — see docs/scenes.md.

mod scenes;
mod spdlib;

use scenes::*;
use spdlib::Lib;

use super::{nff, Scene, SceneError};

type C3 = [f64; 3];
type C4 = [f64; 4];
type Mat = [[f64; 4]; 4];

// The SPD's `PI` (def.h's 3.141592653589793) is `std::f64::consts::PI`,
// the same double.
/// def.h's `EPSILON` and `EPSILON2` (non-Mac values).
const EPSILON: f64 = 1.0e-8;
const EPSILON2: f64 = 1.0e-6;

const X_AXIS: usize = 0;
const Y_AXIS: usize = 1;
const Z_AXIS: usize = 2;

/// A generator: its name, the SPD's default size, the largest size this
/// port accepts (to keep files and memory reasonable) and the function.
struct Generator {
    name: &'static str,
    default_size: u32,
    max_size: u32,
    run: fn(&mut Lib, u32),
}

const GENERATORS: &[Generator] = &[
    Generator {
        name: "balls",
        default_size: 4,
        max_size: 6,
        run: balls,
    },
    Generator {
        name: "gears",
        default_size: 4,
        max_size: 12,
        run: gears,
    },
    Generator {
        name: "jacks",
        default_size: 1,
        max_size: 6,
        run: jacks,
    },
    Generator {
        name: "lattice",
        default_size: 12,
        max_size: 40,
        run: lattice,
    },
    Generator {
        name: "mount",
        default_size: 6,
        // The SPD's hash shifts by 7 - size: larger sizes are undefined in C.
        max_size: 7,
        run: mount,
    },
    Generator {
        name: "rings",
        default_size: 7,
        max_size: 24,
        run: rings,
    },
    Generator {
        name: "shells",
        default_size: 5,
        max_size: 10,
        run: shells,
    },
    Generator {
        name: "tetra",
        default_size: 6,
        max_size: 9,
        run: tetra,
    },
    Generator {
        name: "tree",
        default_size: 11,
        max_size: 16,
        run: tree,
    },
];

/// Names of the generators, alphabetical.
pub fn names() -> Vec<&'static str> {
    GENERATORS.iter().map(|g| g.name).collect()
}

fn find(name: &str) -> Result<&'static Generator, String> {
    GENERATORS.iter().find(|g| g.name == name).ok_or_else(|| {
        format!(
            "unknown SPD generator '{name}': expected one of {}",
            names().join(", ")
        )
    })
}

/// The SPD program's default size factor for `name`.
pub fn default_size(name: &str) -> Result<u32, String> {
    Ok(find(name)?.default_size)
}

/// Whether `size` is a size factor `name` takes.
pub fn check_size(name: &str, size: u32) -> Result<(), String> {
    let g = find(name)?;
    if size < 1 || size > g.max_size {
        return Err(format!(
            "size {size} for {name}: expected 1 to {} (the SPD default is {})",
            g.max_size, g.default_size
        ));
    }
    Ok(())
}

/// The NFF text the SPD program `name` prints at size factor `size`.
pub fn generate(name: &str, size: u32) -> Result<String, String> {
    check_size(name, size)?;
    let g = find(name)?;
    let mut lib = Lib::new();
    (g.run)(&mut lib, size);
    Ok(lib.out)
}

/// The scene the SPD program `name` describes at size factor `size`,
/// read back through the NFF reader (source `name-size.nff`).
pub fn scene(name: &str, size: u32) -> Result<Scene, SceneError> {
    let file = format!("{name}-{size}.nff");
    let text = generate(name, size).map_err(|message| SceneError {
        file: file.clone(),
        line: 0,
        col: 0,
        message,
    })?;
    nff::parse(&text, &file)
}

// ---------------------------------------------------------------------------
// C's printf("%g")

/// `x` formatted as C's `%g`: 6 significant digits, trailing zeros removed,
/// exponent form when the exponent is below -4 or at least 6.
pub fn fmt_g(x: f64) -> String {
    if x == 0.0 {
        return if x.is_sign_negative() { "-0" } else { "0" }.into();
    }
    if x.is_nan() {
        return if x.is_sign_negative() { "-nan" } else { "nan" }.into();
    }
    if x.is_infinite() {
        return if x < 0.0 { "-inf" } else { "inf" }.into();
    }
    let e = format!("{x:.5e}");
    let (mant, exp) = e.split_once('e').expect("exponent form");
    let exp: i32 = exp.parse().expect("exponent");
    if !(-4..6).contains(&exp) {
        let sign = if exp < 0 { '-' } else { '+' };
        format!("{}e{sign}{:02}", strip_zeros(mant), exp.abs())
    } else {
        strip_zeros(&format!("{x:.*}", (5 - exp) as usize)).to_string()
    }
}

fn strip_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::spdlib::gauss_rand;
    use super::*;

    #[test]
    fn percent_g_matches_c() {
        // Values and their glibc printf("%g") text.
        let cases = [
            (0.0, "0"),
            (-0.0, "-0"),
            (1.0, "1"),
            (100000.0, "100000"),
            (1000000.0, "1e+06"),
            (0.0001, "0.0001"),
            (0.00001234, "1.234e-05"),
            (3.0827, "3.0827"),
            (-0.7047694, "-0.704769"),
            (123456.5, "123456"),
            (123457.5, "123458"),
            (1.0e-300, "1e-300"),
            (2.5e10, "2.5e+10"),
            (0.078, "0.078"),
        ];
        for (x, want) in cases {
            assert_eq!(fmt_g(x), want, "{x}");
        }
    }

    #[test]
    fn bad_names_and_sizes_are_errors() {
        assert!(generate("nope", 1)
            .unwrap_err()
            .contains("unknown SPD generator"));
        assert!(generate("balls", 0).unwrap_err().contains("size 0"));
        assert!(generate("balls", 99).unwrap_err().contains("size 99"));
    }

    #[test]
    fn gauss_rand_is_deterministic_and_in_range() {
        let a = gauss_rand(21);
        assert_eq!(a, gauss_rand(21));
        assert!(a.is_finite() && a.abs() < 10.0);
    }
}
