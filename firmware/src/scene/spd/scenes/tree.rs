//! tree.c: Aono & Kunii's tree of cones and spheres.

use std::f64::consts::PI;

use super::super::spdlib::*;
use super::super::{Mat, X_AXIS, Z_AXIS};
use super::LSCALE_NFF;

pub(crate) fn tree(lib: &mut Lib, size: u32) {
    const BR_ANGLE_0: f64 = 40.0;
    const BR_ANGLE_1: f64 = 25.0;
    const BR_CONTR_0: f64 = 0.65;
    const BR_CONTR_1: f64 = 0.70;
    const BR_DIAMETER: f64 = 0.67;
    const DIV_ANGLE: f64 = 140.0;
    const WIDTH_HEIGHTH_RATIO: f64 = 0.15;

    pub(super) fn grow_tree(lib: &mut Lib, rst: &[Mat; 2], cur: &Mat, scale: f64, depth: u32) {
        let b = transform_point(&[0.0, 0.0, 0.0], cur);
        let base = [b[0], b[1], b[2], scale * WIDTH_HEIGHTH_RATIO];
        let a = transform_point(&[0.0, 0.0, 1.0], cur);
        let apex = [a[0], a[1], a[2], base[3] * BR_DIAMETER];
        lib.cylcone(base, apex);
        lib.sphere(apex);
        if depth > 0 {
            for r in rst {
                let new_mx = matrix_multiply(r, cur);
                grow_tree(lib, rst, &new_mx, scale * BR_DIAMETER, depth - 1);
            }
        }
    }

    lib.background([0.078, 0.361, 0.753]);
    lib.viewpoint(
        [4.5, 0.4, 2.0],
        [0.0, 0.0, 1.5],
        [0.0, 0.0, 1.0],
        45.0,
        1.0,
        1.0,
        512,
        512,
    );
    for l in [
        [-5.0, 5.0, 50.0],
        [30.0, -30.0, 30.0],
        [-40.0, -30.0, 20.0],
        [10.0, 30.0, 40.0],
        [-30.0, 40.0, 10.0],
        [50.0, 25.0, 20.0],
        [-10.0, -60.0, 30.0],
    ] {
        lib.light([l[0], l[1], l[2], LSCALE_NFF]);
    }
    lib.color([0.2, 0.7, 0.2], 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let mut field = [
        [50.0, 50.0, 0.0],
        [-50.0, 50.0, 0.0],
        [-50.0, -50.0, 0.0],
        [50.0, -50.0, 0.0],
    ];
    lib.polygon(&mut field);
    lib.color([0.55, 0.4, 0.2], 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let mut rst = [zero_matrix(); 2];
    for (i, r) in rst.iter_mut().enumerate() {
        let (branch_angle, divergence, contraction) = if i == 0 {
            (BR_ANGLE_0, 90.0, BR_CONTR_0)
        } else {
            (BR_ANGLE_1, DIV_ANGLE + 90.0, BR_CONTR_1)
        };
        let t1 = rotate_matrix(X_AXIS, branch_angle * PI / 180.0);
        let t2 = rotate_matrix(Z_AXIS, divergence * PI / 180.0);
        let tr = matrix_multiply(&t1, &t2);
        let mut st = identity_matrix();
        st[0][0] = contraction;
        st[1][1] = contraction;
        st[2][2] = contraction;
        st[3][2] = 1.0;
        *r = matrix_multiply(&tr, &st);
    }
    grow_tree(lib, &rst, &identity_matrix(), 1.0, size);
}
