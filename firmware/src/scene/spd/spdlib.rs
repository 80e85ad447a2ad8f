//! The SPD's C library, ported: libvec.c (vectors and 4x4 matrices, row
//! vectors `p' = p * M`), the random numbers of `mount`, and libpr*.c /
//! libply.c / libtx.c (NFF output and the transform stack).

use std::fmt::Write as _;

use super::{fmt_g, Mat, C3, C4, EPSILON, EPSILON2, X_AXIS, Y_AXIS};
use std::f64::consts::PI;

// ---------------------------------------------------------------------------
// libvec.c: vectors and 4x4 matrices (row vectors, `p' = p * M`)

pub(super) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(super) fn cross(a: &[f64], b: &[f64]) -> C3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `lib_normalize_vector`: normalizes in place, returns the length.
pub(super) fn normalize(v: &mut [f64]) -> f64 {
    let d = dot(v, v).sqrt();
    if d > 0.0 {
        v[0] /= d;
        v[1] /= d;
        v[2] /= d;
    }
    d
}

pub(super) fn zero_matrix() -> Mat {
    [[0.0; 4]; 4]
}

pub(super) fn identity_matrix() -> Mat {
    let mut m = zero_matrix();
    for (i, row) in m.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    m
}

pub(super) fn rotate_matrix(axis: usize, angle: f64) -> Mat {
    let mut mx = zero_matrix();
    let cosine = angle.cos();
    let sine = angle.sin();
    match axis {
        X_AXIS => {
            mx[0][0] = 1.0;
            mx[1][1] = cosine;
            mx[2][2] = cosine;
            mx[1][2] = sine;
            mx[2][1] = -sine;
        }
        Y_AXIS => {
            mx[1][1] = 1.0;
            mx[0][0] = cosine;
            mx[2][2] = cosine;
            mx[2][0] = sine;
            mx[0][2] = -sine;
        }
        _ => {
            mx[2][2] = 1.0;
            mx[0][0] = cosine;
            mx[1][1] = cosine;
            mx[0][1] = sine;
            mx[1][0] = -sine;
        }
    }
    mx[3][3] = 1.0;
    mx
}

pub(super) fn axis_rotate_matrix(axis: &[f64], angle: f64) -> Mat {
    let cosine = angle.cos();
    let sine = angle.sin();
    let omc = 1.0 - cosine;
    let sqr = |a: f64| a * a;
    let (x, y, z) = (axis[0], axis[1], axis[2]);
    [
        [
            sqr(x) + (1.0 - sqr(x)) * cosine,
            x * y * omc + z * sine,
            x * z * omc - y * sine,
            0.0,
        ],
        [
            x * y * omc - z * sine,
            sqr(y) + (1.0 - sqr(y)) * cosine,
            y * z * omc + x * sine,
            0.0,
        ],
        [
            x * z * omc + y * sine,
            y * z * omc - x * sine,
            sqr(z) + (1.0 - sqr(z)) * cosine,
            0.0,
        ],
        [0.0, 0.0, 0.0, 1.0],
    ]
}

pub(super) fn translate_matrix(v: &[f64]) -> Mat {
    let mut mx = identity_matrix();
    mx[3][0] = v[0];
    mx[3][1] = v[1];
    mx[3][2] = v[2];
    mx
}

pub(super) fn scale_matrix(v: &[f64]) -> Mat {
    let mut mx = zero_matrix();
    mx[0][0] = v[0];
    mx[1][1] = v[1];
    mx[2][2] = v[2];
    mx[3][3] = 1.0;
    mx
}

pub(super) fn matrix_multiply(a: &Mat, b: &Mat) -> Mat {
    let mut r = zero_matrix();
    for i in 0..4 {
        for j in 0..4 {
            r[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j] + a[i][3] * b[3][j];
        }
    }
    r
}

pub(super) fn transform_vector(v: &[f64], mx: &Mat) -> C3 {
    [
        v[0] * mx[0][0] + v[1] * mx[1][0] + v[2] * mx[2][0],
        v[0] * mx[0][1] + v[1] * mx[1][1] + v[2] * mx[2][1],
        v[0] * mx[0][2] + v[1] * mx[1][2] + v[2] * mx[2][2],
    ]
}

pub(super) fn transform_point(v: &[f64], mx: &Mat) -> C3 {
    [
        v[0] * mx[0][0] + v[1] * mx[1][0] + v[2] * mx[2][0] + mx[3][0],
        v[0] * mx[0][1] + v[1] * mx[1][1] + v[2] * mx[2][1] + mx[3][1],
        v[0] * mx[0][2] + v[1] * mx[1][2] + v[2] * mx[2][2] + mx[3][2],
    ]
}

pub(super) fn transform_coord(v: &C4, mx: &Mat) -> C4 {
    [
        v[0] * mx[0][0] + v[1] * mx[1][0] + v[2] * mx[2][0] + v[3] * mx[3][0],
        v[0] * mx[0][1] + v[1] * mx[1][1] + v[2] * mx[2][1] + v[3] * mx[3][1],
        v[0] * mx[0][2] + v[1] * mx[1][2] + v[2] * mx[2][2] + v[3] * mx[3][2],
        v[0] * mx[0][3] + v[1] * mx[1][3] + v[2] * mx[2][3] + v[3] * mx[3][3],
    ]
}

/// `lib_gauss_rand`: the SPD's portable Gaussian random number generator
/// (Numerical Recipes' GASDEV on a small linear congruential generator).
pub(super) fn gauss_rand(iseed: i64) -> f64 {
    const M1: i64 = 134456;
    const IA1: i64 = 8121;
    const IC1: i64 = 28411;
    const RM1: f64 = 1.0 / M1 as f64;
    let mut ix2 = iseed;
    let (mut v1, mut r);
    loop {
        let ix1 = (IC1 + ix2 * IA1) % M1;
        ix2 = (IC1 + ix1 * IA1) % M1;
        v1 = ix1 as f64 * 2.0 * RM1 - 1.0;
        let v2 = ix2 as f64 * 2.0 * RM1 - 1.0;
        r = v1 * v1 + v2 * v2;
        if r < 1.0 {
            break;
        }
    }
    let fac = (-2.0 * r.ln() / r).sqrt();
    v1 * fac
}

// ---------------------------------------------------------------------------
// libpr*.c / libply.c / libtx.c: NFF output and the transform stack

pub(super) struct Lib {
    pub(super) out: String,
    pub(super) tx: Mat,
    pub(super) stack: Vec<Mat>,
}

impl Lib {
    pub(super) fn new() -> Self {
        Lib {
            out: String::new(),
            tx: identity_matrix(),
            stack: Vec::new(),
        }
    }

    pub(super) fn line(&mut self, kw: &str, vals: &[f64]) {
        self.out.push_str(kw);
        for v in vals {
            self.out.push(' ');
            self.out.push_str(&fmt_g(*v));
        }
        self.out.push('\n');
    }

    pub(super) fn background(&mut self, c: C3) {
        self.line("b", &c);
    }

    #[allow(clippy::too_many_arguments)]
    pub(super) fn viewpoint(
        &mut self,
        from: C3,
        at: C3,
        up: C3,
        fov: f64,
        _aspect: f64,
        hither: f64,
        resx: u32,
        resy: u32,
    ) {
        self.out.push_str("v\n");
        self.line("from", &from);
        self.line("at", &at);
        self.line("up", &up);
        self.line("angle", &[fov]);
        self.line("hither", &[hither]);
        let _ = writeln!(self.out, "resolution {resx} {resy}");
    }

    /// `lib_output_light`: an active transform moves the light as a
    /// vector (no translation), as the SPD does.
    pub(super) fn light(&mut self, c: C4) {
        let mut v = [c[0], c[1], c[2]];
        if self.tx_active() {
            v = transform_vector(&v, &self.tx);
        }
        self.line("l", &v);
    }

    /// `lib_output_color`: NFF `f r g b Kd Ks Shine T ior`, the Phong
    /// exponent derived from the highlight half-angle `ang` (degrees).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn color(
        &mut self,
        color: C3,
        _ka: f64,
        kd: f64,
        ks: f64,
        _ks_spec: f64,
        ang: f64,
        kt: f64,
        ior: f64,
    ) {
        let ang_radians = PI * ang / 180.0;
        let phong_pow = if ang_radians <= 0.0 {
            100000.0
        } else if ang_radians >= PI / 2.0 {
            1.0
        } else {
            0.5f64.ln() / ang_radians.cos().ln()
        };
        self.line(
            "f",
            &[color[0], color[1], color[2], kd, ks, phong_pow, kt, ior],
        );
    }

    pub(super) fn tx_active(&self) -> bool {
        for i in 0..4 {
            for j in 0..4 {
                let id = if i == j { 1.0 } else { 0.0 };
                if (self.tx[i][j] - id).abs() > EPSILON {
                    return true;
                }
            }
        }
        false
    }

    /// `lib_tx_unwind`'s X scale factor (the length of the first row of
    /// the normalized 3x3 part); only its absolute value is used.
    pub(super) fn tx_scale_x(&self) -> f64 {
        let mut loc = self.tx;
        if loc[3][3] != 0.0 {
            let w = loc[3][3];
            for row in loc.iter_mut() {
                for v in row.iter_mut() {
                    *v /= w;
                }
            }
        }
        let mut row0 = [loc[0][0], loc[0][1], loc[0][2]];
        normalize(&mut row0)
    }

    pub(super) fn sphere(&mut self, c: C4) {
        let mut c = c;
        if self.tx_active() {
            let s = self.tx_scale_x();
            let p = transform_point(&c, &self.tx);
            c = [p[0], p[1], p[2], c[3] * s.abs()];
        }
        self.line("s", &c);
    }

    pub(super) fn cylcone(&mut self, base: C4, apex: C4) {
        let (mut base, mut apex) = (base, apex);
        if self.tx_active() {
            let s = self.tx_scale_x();
            let p = transform_point(&base, &self.tx);
            base = [p[0], p[1], p[2], base[3] * s.abs()];
            let p = transform_point(&apex, &self.tx);
            apex = [p[0], p[1], p[2], apex[3] * s.abs()];
        }
        self.line(
            "c",
            &[
                base[0], base[1], base[2], base[3], apex[0], apex[1], apex[2], apex[3],
            ],
        );
    }

    /// `lib_output_polygon`: adjacent coincident vertices are merged (in
    /// the caller's array, as in C), fewer than 3 left means no polygon.
    pub(super) fn polygon(&mut self, vert: &mut [C3]) {
        let mut tot = vert.len();
        let mut i = 0;
        while i < tot {
            let a = vert[i];
            let b = vert[(i + 1) % tot];
            let mut x = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
            if normalize(&mut x) < EPSILON2 {
                for j in i..tot - 1 {
                    vert[j] = vert[j + 1];
                }
                tot -= 1;
            } else {
                i += 1;
            }
        }
        if tot < 3 {
            return;
        }
        if self.tx_active() {
            for v in vert.iter_mut().take(tot) {
                *v = transform_point(v, &self.tx);
            }
        }
        let _ = writeln!(self.out, "p {tot}");
        for v in vert.iter().take(tot) {
            self.line_vals(v);
        }
    }

    pub(super) fn line_vals(&mut self, vals: &[f64]) {
        let s: Vec<String> = vals.iter().map(|v| fmt_g(*v)).collect();
        self.out.push_str(&s.join(" "));
        self.out.push('\n');
    }

    pub(super) fn tx_push(&mut self) {
        self.stack.push(self.tx);
    }

    pub(super) fn tx_pop(&mut self) {
        if let Some(m) = self.stack.pop() {
            self.tx = m;
        }
    }

    pub(super) fn tx_rotate(&mut self, axis: usize, angle: f64) {
        self.tx = matrix_multiply(&rotate_matrix(axis, angle), &self.tx);
    }

    pub(super) fn tx_scale(&mut self, v: C3) {
        self.tx = matrix_multiply(&scale_matrix(&v), &self.tx);
    }

    pub(super) fn tx_translate(&mut self, v: C3) {
        self.tx = matrix_multiply(&translate_matrix(&v), &self.tx);
    }
}
