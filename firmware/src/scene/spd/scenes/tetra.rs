//! tetra.c: recursive tetrahedral pyramid.

use super::super::spdlib::*;
use super::super::C4;
use super::LSCALE_NFF;

pub(crate) fn tetra(lib: &mut Lib, size: u32) {
    pub(super) fn create_tetra(lib: &mut Lib, depth: u32, center: C4) {
        if depth <= 1 {
            let mut obj_pt = [[0.0; 3]; 4];
            let mut n = 0;
            for x in [-1i32, 1] {
                for y in [-1i32, 1] {
                    for z in [-1i32, 1] {
                        if x * y * z == 1 {
                            obj_pt[n] = [
                                center[0] + x as f64 * center[3],
                                center[1] + y as f64 * center[3],
                                center[2] + z as f64 * center[3],
                            ];
                            n += 1;
                        }
                    }
                }
            }
            for face in 0..4 {
                let mut ord = [face % 4, (face + 1) % 4, (face + 2) % 4];
                if face % 2 == 1 {
                    ord.swap(0, 2);
                }
                let mut pts = [obj_pt[ord[0]], obj_pt[ord[1]], obj_pt[ord[2]]];
                lib.polygon(&mut pts);
            }
        } else {
            for x in [-1i32, 1] {
                for y in [-1i32, 1] {
                    for z in [-1i32, 1] {
                        if x * y * z == 1 {
                            let sub = [
                                center[0] + x as f64 * center[3] / 2.0,
                                center[1] + y as f64 * center[3] / 2.0,
                                center[2] + z as f64 * center[3] / 2.0,
                                center[3] / 2.0,
                            ];
                            create_tetra(lib, depth - 1, sub);
                        }
                    }
                }
            }
        }
    }

    lib.background([0.078, 0.361, 0.753]);
    lib.viewpoint(
        [1.022846, -3.177154, -2.174512],
        [-0.004103, -0.004103, 0.216539],
        [-0.816497, -0.816497, 0.816497],
        45.0,
        1.0,
        1.0,
        512,
        512,
    );
    lib.light([2.0, -18.0, -5.0, LSCALE_NFF]);
    lib.color([1.0, 0.2, 0.2], 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    create_tetra(lib, size, [0.0, 0.0, 0.0, 1.0]);
}
