//! mount.c: Carpenter's fractal mountain and four glass spheres.

use std::f64::consts::PI;

use super::super::spdlib::*;
use super::super::{C4, Z_AXIS};
use super::LSCALE_NFF;

const FRACTAL_DIMENSION: f64 = 2.2;
const MOUNTAIN_NO: i64 = 21;
const X_CORNER: f64 = -1.0;
const Y_CORNER: f64 = -1.0;
const WIDTH: f64 = 2.0;

/// The original (repeating) hash, kept as the SPD does for comparable
/// images.
fn hash_rand(a: i64, b: i64, c: u32) -> i64 {
    let (a, b) = (a as u64, b as u64);
    (((a << (23 - c)) + (b << (15 - c)) + (a << (7 - c))) & 0xffff) as i64
}

fn create_spheres(lib: &mut Lib, center: C4) {
    let mut axis = [1.0, 1.0, 0.0];
    normalize(&mut axis);
    let angle = (-1.0f64 / 3.0).acos();
    let pt = [0.0, 0.0, center[3] * (3.0f64 / 2.0).sqrt()];
    lib.sphere([
        center[0] + pt[0],
        center[1] + pt[1],
        center[2] + pt[2],
        center[3],
    ]);
    let mx = axis_rotate_matrix(&axis, angle);
    let new_pt = transform_vector(&pt, &mx);
    for i in 0..3 {
        let mx = rotate_matrix(Z_AXIS, i as f64 * 2.0 * PI / 3.0);
        let s = transform_vector(&new_pt, &mx);
        lib.sphere([
            s[0] + center[0],
            s[1] + center[1],
            s[2] + center[2],
            center[3],
        ]);
    }
}

struct M {
    size: u32,
    roughness: f64,
}

#[allow(clippy::too_many_arguments)]
fn grow_mountain(
    lib: &mut Lib,
    m: &M,
    fnum_pts: f64,
    width: i64,
    ll_x: i64,
    ll_y: i64,
    ll_fz: f64,
    lr_fz: f64,
    ur_fz: f64,
    ul_fz: f64,
) {
    if width == 1 {
        let l_fx = X_CORNER + ll_x as f64 * WIDTH / fnum_pts;
        let r_fx = X_CORNER + (ll_x + 1) as f64 * WIDTH / fnum_pts;
        let l_fy = Y_CORNER + ll_y as f64 * WIDTH / fnum_pts;
        let u_fy = Y_CORNER + (ll_y + 1) as f64 * WIDTH / fnum_pts;
        for num_tri in 0..2 {
            let mut tri = [[0.0; 3]; 3];
            for (num_vert, v) in tri.iter_mut().enumerate() {
                *v = match (num_vert + num_tri * 2) % 4 {
                    0 => [l_fx, l_fy, ll_fz],
                    1 => [r_fx, l_fy, lr_fz],
                    2 => [r_fx, u_fy, ur_fz],
                    _ => [l_fx, u_fy, ul_fz],
                };
            }
            lib.polygon(&mut tri);
        }
    } else {
        let half = width >> 1;
        let hside_length = half as f64 * WIDTH / fnum_pts;
        let rise_height = hside_length * m.roughness;
        let sf = m.size;
        let iz = MOUNTAIN_NO + hash_rand(ll_x + half, ll_y, sf);
        let lower_fz = (ll_fz + lr_fz) / 2.0 + rise_height * gauss_rand(iz);
        let iz = MOUNTAIN_NO + hash_rand(ll_x + width, ll_y + half, sf);
        let right_fz = (lr_fz + ur_fz) / 2.0 + rise_height * gauss_rand(iz);
        let iz = MOUNTAIN_NO + hash_rand(ll_x + half, ll_y + width, sf);
        let upper_fz = (ur_fz + ul_fz) / 2.0 + rise_height * gauss_rand(iz);
        let iz = MOUNTAIN_NO + hash_rand(ll_x, ll_y + half, sf);
        let left_fz = (ul_fz + ll_fz) / 2.0 + rise_height * gauss_rand(iz);
        let iz = MOUNTAIN_NO + hash_rand(ll_x + half, ll_y + half, sf);
        // mount.c's literal 1.4142136, not sqrt(2) to the last bit.
        #[allow(clippy::approx_constant)]
        const ROOT2: f64 = 1.4142136;
        let middle_fz =
            (ll_fz + lr_fz + ur_fz + ul_fz) / 4.0 + ROOT2 * rise_height * gauss_rand(iz);
        grow_mountain(
            lib, m, fnum_pts, half, ll_x, ll_y, ll_fz, lower_fz, middle_fz, left_fz,
        );
        grow_mountain(
            lib,
            m,
            fnum_pts,
            half,
            ll_x + half,
            ll_y,
            lower_fz,
            lr_fz,
            right_fz,
            middle_fz,
        );
        grow_mountain(
            lib,
            m,
            fnum_pts,
            half,
            ll_x + half,
            ll_y + half,
            middle_fz,
            right_fz,
            ur_fz,
            upper_fz,
        );
        grow_mountain(
            lib,
            m,
            fnum_pts,
            half,
            ll_x,
            ll_y + half,
            left_fz,
            middle_fz,
            upper_fz,
            ul_fz,
        );
    }
}

/// mount.c's `main`: the view, the lights, the spheres and the mountain
/// of `4^size` squares.
pub(crate) fn mount(lib: &mut Lib, size: u32) {
    lib.background([0.078, 0.361, 0.753]);
    lib.viewpoint(
        [-1.6, 1.6, 1.7],
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        45.0,
        1.0,
        0.01,
        512,
        512,
    );
    lib.light([-100.0, -100.0, 100.0, LSCALE_NFF]);
    lib.color([1.0, 1.0, 1.0], 0.0, 0.1, 0.1, 0.4, 6.7, 0.9, 1.5);
    create_spheres(lib, [-0.8, 0.8, 1.00, 0.17]);
    lib.color([0.5, 0.45, 0.35], 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let num_pts: i64 = 1 << size;
    let ratio = 2.0 / (2.0f64.ln() / (FRACTAL_DIMENSION - 1.0)).exp();
    let m = M {
        size,
        roughness: (ratio * ratio - 1.0).sqrt(),
    };
    grow_mountain(lib, &m, num_pts as f64, num_pts, 0, 0, 0.0, 0.0, 0.0, 0.0);
}
