//! A bounding volume hierarchy over the scene's objects, the reference
//! renderer's acceleration structure (the chip uses the firmware's BSP;
//! the reference only has to be exact and fast).

use firmware::scene::{Aabb, Scene, Vec3};

use super::shapes::{intersect, Ray, SurfaceHit};

const LEAF_SIZE: usize = 4;

#[derive(Clone, Debug)]
struct Node {
    bounds: Aabb,
    /// Leaf: `count > 0`, objects `first..first + count` of `order`.
    /// Inner: `count == 0`, children `first` and `first + 1`.
    first: u32,
    count: u32,
}

/// The hierarchy; `two_sided[i]` marks transmitting objects.
pub(crate) struct Bvh {
    nodes: Vec<Node>,
    order: Vec<u32>,
    two_sided: Vec<bool>,
}

impl Bvh {
    pub fn build(scene: &Scene) -> Bvh {
        let bounds: Vec<Aabb> = scene.objects.iter().map(|o| o.shape.bounds()).collect();
        let two_sided = scene
            .objects
            .iter()
            .map(|o| scene.materials[o.material].t > 0.0)
            .collect();
        let mut order: Vec<u32> = (0..bounds.len() as u32).collect();
        let mut nodes = vec![Node {
            bounds: Aabb::EMPTY,
            first: 0,
            count: 0,
        }];
        if !bounds.is_empty() {
            build(&mut nodes, 0, &mut order, 0, &bounds);
        }
        Bvh {
            nodes,
            order,
            two_sided,
        }
    }

    /// Nearest visible hit: (object index, hit).
    pub fn closest(
        &self,
        scene: &Scene,
        r: &Ray,
        tmin: f64,
        tmax: f64,
    ) -> Option<(usize, SurfaceHit)> {
        if self.order.is_empty() {
            return None;
        }
        let inv = Vec3::new(1.0 / r.d.x, 1.0 / r.d.y, 1.0 / r.d.z);
        let mut best: Option<(usize, SurfaceHit)> = None;
        let mut tmax = tmax;
        let mut stack = [0u32; 64];
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            let node = &self.nodes[stack[sp] as usize];
            if slab(&node.bounds, r, &inv, tmin, tmax).is_none() {
                continue;
            }
            if node.count > 0 {
                for &i in &self.order[node.first as usize..(node.first + node.count) as usize] {
                    let i = i as usize;
                    if let Some(h) =
                        intersect(&scene.objects[i].shape, r, tmin, tmax, self.two_sided[i])
                    {
                        // Equal t: the lower object index wins, whatever the
                        // traversal order.
                        if best.is_none_or(|(bi, bh)| h.t < bh.t || (h.t == bh.t && i < bi)) {
                            tmax = h.t;
                            best = Some((i, h));
                        }
                    }
                }
            } else {
                let (a, b) = (node.first, node.first + 1);
                let ta = slab(&self.nodes[a as usize].bounds, r, &inv, tmin, tmax);
                let tb = slab(&self.nodes[b as usize].bounds, r, &inv, tmin, tmax);
                // Push the farther child first so the nearer is popped first.
                match (ta, tb) {
                    (Some(x), Some(y)) => {
                        let (near, far) = if x <= y { (a, b) } else { (b, a) };
                        stack[sp] = far;
                        stack[sp + 1] = near;
                        sp += 2;
                    }
                    (Some(_), None) => {
                        stack[sp] = a;
                        sp += 1;
                    }
                    (None, Some(_)) => {
                        stack[sp] = b;
                        sp += 1;
                    }
                    (None, None) => {}
                }
            }
        }
        best
    }

    /// Is anything visible hit in `(tmin, tmax)`?
    pub fn occluded(&self, scene: &Scene, r: &Ray, tmin: f64, tmax: f64) -> bool {
        if self.order.is_empty() {
            return false;
        }
        let inv = Vec3::new(1.0 / r.d.x, 1.0 / r.d.y, 1.0 / r.d.z);
        let mut stack = [0u32; 64];
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            let node = &self.nodes[stack[sp] as usize];
            if slab(&node.bounds, r, &inv, tmin, tmax).is_none() {
                continue;
            }
            if node.count > 0 {
                for &i in &self.order[node.first as usize..(node.first + node.count) as usize] {
                    let i = i as usize;
                    if intersect(&scene.objects[i].shape, r, tmin, tmax, self.two_sided[i])
                        .is_some()
                    {
                        return true;
                    }
                }
            } else {
                stack[sp] = node.first;
                stack[sp + 1] = node.first + 1;
                sp += 2;
            }
        }
        false
    }
}

/// Entry distance of the ray into the box within `(tmin, tmax)`, if any.
/// Boxes are padded by a relative epsilon so that flat boxes (polygons in a
/// coordinate plane) and rounding never lose a hit.
fn slab(b: &Aabb, r: &Ray, inv: &Vec3, tmin: f64, tmax: f64) -> Option<f64> {
    let (mut t0, mut t1) = (tmin, tmax);
    for ax in 0..3 {
        let (lo, hi) = (b.min.axis(ax), b.max.axis(ax));
        let pad = 1e-9 * (1.0 + lo.abs().max(hi.abs()));
        let (o, i) = (r.o.axis(ax), inv.axis(ax));
        let (mut ta, mut tb) = ((lo - pad - o) * i, (hi + pad - o) * i);
        if ta > tb {
            std::mem::swap(&mut ta, &mut tb);
        }
        // NaN (0 * inf when the origin is on a slab plane) never narrows.
        if ta > t0 {
            t0 = ta;
        }
        if tb < t1 {
            t1 = tb;
        }
        if t0 > t1 {
            return None;
        }
    }
    Some(t0)
}

fn build(nodes: &mut Vec<Node>, at: usize, order: &mut [u32], offset: usize, bounds: &[Aabb]) {
    let bb = order
        .iter()
        .fold(Aabb::EMPTY, |b, &i| b.union(bounds[i as usize]));
    if order.len() <= LEAF_SIZE {
        nodes[at] = Node {
            bounds: bb,
            first: offset as u32,
            count: order.len() as u32,
        };
        return;
    }
    // Median split along the longest axis of the centroids.
    let cb = Aabb::from_points(order.iter().map(|&i| bounds[i as usize].center()));
    let e = cb.extent();
    let ax = if e.x >= e.y && e.x >= e.z {
        0
    } else if e.y >= e.z {
        1
    } else {
        2
    };
    let mid = order.len() / 2;
    order.select_nth_unstable_by(mid, |&a, &b| {
        let (ca, cb) = (
            bounds[a as usize].center().axis(ax),
            bounds[b as usize].center().axis(ax),
        );
        ca.total_cmp(&cb).then(a.cmp(&b))
    });
    let first = nodes.len();
    nodes.push(Node {
        bounds: Aabb::EMPTY,
        first: 0,
        count: 0,
    });
    nodes.push(Node {
        bounds: Aabb::EMPTY,
        first: 0,
        count: 0,
    });
    nodes[at] = Node {
        bounds: bb,
        first: first as u32,
        count: 0,
    };
    let (l, r) = order.split_at_mut(mid);
    build(nodes, first, l, offset, bounds);
    build(nodes, first + 1, r, offset + mid, bounds);
}
