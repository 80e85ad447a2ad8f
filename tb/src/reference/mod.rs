//! The float reference renderer: the golden model every chip image is
//! measured against.
//!
//! Whitted ray tracing in `f64` with the SPD's rules
//! (`scenes/spd/README.md`): one-sided primitives (two-sided when
//! transmitting), no shadow ray where the shading normal faces away from
//! the light, Phong highlights, a reflection ray from every surface with
//! Ks > 0 or T > 0, a refraction ray (Snell's law) from every transmitting
//! surface unless the ray is totally internally reflected, and a maximum
//! ray depth (the eye ray has depth 1).
//!
//! Shading, per NFF: colour = sum over unshadowed lights of
//! `light * (Kd * colour * N.L + Ks * (R.V)^Shine)` + `Ks * reflected` +
//! `T * refracted`; no ambient term; a light with no colour has intensity
//! `1/sqrt(number of lights)`; a ray that hits nothing gets the background.
//! Shadow rays are stopped by any visible surface (transmitting ones too).
//!
//! Every pixel is computed on its own from the scene alone, rows in
//! parallel with rayon, so an image is bit-identical whatever the number of
//! threads; the ray counts are integers summed per row.

pub mod bvh;
pub mod shapes;

use firmware::scene::{Scene, Vec3};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;

use self::bvh::Bvh;
use self::shapes::Ray;

/// How to render.
#[derive(Clone, Debug)]
pub struct Options {
    pub width: u32,
    pub height: u32,
    /// Maximum ray depth; the eye ray has depth 1.
    pub max_depth: u32,
    /// Shoot rays through pixel corners ((w+1) x (h+1) eye rays, as the SPD
    /// prescribes); a pixel is then the mean of its four corners. Otherwise
    /// one ray through each pixel centre.
    pub corners: bool,
    /// Show a progress bar (only drawn on a terminal).
    pub progress: bool,
}

/// The rays a render cast, counted as the SPD counts them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct RayStats {
    pub eye_rays: u64,
    pub eye_hit_rays: u64,
    pub reflect_rays: u64,
    pub refract_rays: u64,
    pub shadow_rays: u64,
    /// The rays whose colour reaches a pixel: the SPD counts a reflection
    /// ray from every surface with Ks > 0 or T > 0, so also those of weight
    /// Ks = 0 and everything under them; the chip traces only these.
    pub live_reflect_rays: u64,
    pub live_refract_rays: u64,
    pub live_shadow_rays: u64,
    /// Which way the live secondary and shadow rays went, and those that
    /// ended (hit, blocked).
    #[serde(skip)]
    pub ways: RayWays,
}

/// Per axis, how many rays went down (`[axis][0]`: a negative direction
/// component) and up (`[axis][1]`), of the live secondary (reflected and
/// refracted) rays and of those that hit something, and of the live
/// shadow rays and of those that were blocked: what the packet
/// traversal's `--child-order auto` serves ([`ray_ways`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayWays {
    pub secondary: [[u64; 2]; 3],
    pub secondary_hit: [[u64; 2]; 3],
    pub shadow: [[u64; 2]; 3],
    pub shadow_blocked: [[u64; 2]; 3],
}

impl RayWays {
    /// Count direction `d` in `counts`.
    fn add(counts: &mut [[u64; 2]; 3], d: Vec3) {
        for (a, c) in counts.iter_mut().enumerate() {
            c[(d.axis(a) >= 0.0) as usize] += 1;
        }
    }
}

impl std::ops::AddAssign for RayWays {
    fn add_assign(&mut self, o: RayWays) {
        for (m, n) in [
            (&mut self.secondary, o.secondary),
            (&mut self.secondary_hit, o.secondary_hit),
            (&mut self.shadow, o.shadow),
            (&mut self.shadow_blocked, o.shadow_blocked),
        ] {
            for (x, y) in m.iter_mut().flatten().zip(n.iter().flatten()) {
                *x += y;
            }
        }
    }
}

impl std::ops::AddAssign for RayStats {
    fn add_assign(&mut self, o: RayStats) {
        self.eye_rays += o.eye_rays;
        self.eye_hit_rays += o.eye_hit_rays;
        self.reflect_rays += o.reflect_rays;
        self.refract_rays += o.refract_rays;
        self.live_reflect_rays += o.live_reflect_rays;
        self.live_refract_rays += o.live_refract_rays;
        self.live_shadow_rays += o.live_shadow_rays;
        self.shadow_rays += o.shadow_rays;
        self.ways += o.ways;
    }
}

/// Value of [`Image::hits`] for a pixel whose eye ray hit nothing.
pub const NO_HIT: u32 = u32::MAX;

/// A rendered image.
#[derive(Clone, Debug)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    /// Linear RGB, row-major from the top-left, not clamped.
    pub rgb: Vec<Vec3>,
    /// Per pixel, the index (into `Scene::objects`) of the object the eye
    /// ray hit, or [`NO_HIT`]. With corner rays: the pixel's top-left corner.
    pub hits: Vec<u32>,
    pub stats: RayStats,
}

impl Image {
    /// 8-bit RGB: each channel clamped to [0, 1], times 255, rounded.
    pub fn to_rgb8(&self) -> Vec<u8> {
        self.rgb
            .iter()
            .flat_map(|c| [to8(c.x), to8(c.y), to8(c.z)])
            .collect()
    }
}

fn to8(x: f64) -> u8 {
    (x.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// The camera's ray generator.
struct View {
    from: Vec3,
    w: Vec3,
    u: Vec3,
    v: Vec3,
    half: f64,
}

impl View {
    fn new(scene: &Scene) -> View {
        let c = &scene.camera;
        let w = (c.at - c.from).normalized();
        let u = w.cross(c.up).normalized(); // right
        let v = u.cross(w); // up
        View {
            from: c.from,
            w,
            u,
            v,
            half: (c.angle.to_radians() / 2.0).tan(),
        }
    }

    /// Ray through screen position (sx, sy) in [-1, 1] (right, up), the
    /// angle spanning the smaller image dimension, square pixels.
    fn ray(&self, sx: f64, sy: f64) -> Ray {
        let d = self.w + self.u * (sx * self.half) + self.v * (sy * self.half);
        Ray {
            o: self.from,
            d: d.normalized(),
        }
    }
}

/// A scene ready to trace.
pub struct Tracer<'s> {
    scene: &'s Scene,
    bvh: Bvh,
    light_colors: Vec<Vec3>,
    /// Offset of a spawned ray's origin off the surface, in scene units.
    eps: f64,
}

impl<'s> Tracer<'s> {
    pub fn new(scene: &'s Scene) -> Tracer<'s> {
        let n = scene.lights.len().max(1) as f64;
        let light_colors = scene
            .lights
            .iter()
            .map(|l| l.color.unwrap_or(Vec3::ONE * (1.0 / n.sqrt())))
            .collect();
        let b = scene.bounds();
        let extent = if b.is_empty() {
            1.0
        } else {
            b.min.max_abs().max(b.max.max_abs()).max(1e-300)
        };
        Tracer {
            scene,
            bvh: Bvh::build(scene),
            light_colors,
            eps: extent * 1e-9,
        }
    }

    /// Nearest visible hit of a ray: (object index, hit).
    pub fn closest(&self, r: &Ray) -> Option<(usize, shapes::SurfaceHit)> {
        self.bvh.closest(self.scene, r, 0.0, f64::INFINITY)
    }

    /// Colour seen along `r` at `depth` (1 = eye ray), counting rays in
    /// `stats`; returns the colour and the object hit.
    pub fn trace(
        &self,
        r: &Ray,
        depth: u32,
        max_depth: u32,
        stats: &mut RayStats,
    ) -> (Vec3, Option<usize>) {
        self.trace_live(r, depth, max_depth, true, stats)
    }

    /// [`Tracer::trace`]; `live`: the ray's colour reaches the pixel (no
    /// zero weight above it), for the `live_*` counts.
    fn trace_live(
        &self,
        r: &Ray,
        depth: u32,
        max_depth: u32,
        live: bool,
        stats: &mut RayStats,
    ) -> (Vec3, Option<usize>) {
        let hit = self.closest(r);
        if depth > 1 && live {
            RayWays::add(&mut stats.ways.secondary, r.d);
            if hit.is_some() {
                RayWays::add(&mut stats.ways.secondary_hit, r.d);
            }
        }
        let Some((id, h)) = hit else {
            return (self.scene.background, None);
        };
        let obj = &self.scene.objects[id];
        let m = &self.scene.materials[obj.material];
        let p = r.at(h.t);
        // Normals on the side the ray came from.
        let (n, ns) = if h.front { (h.n, h.ns) } else { (-h.n, -h.ns) };
        let view = -r.d;
        let mut color = Vec3::ZERO;
        for (light, lc) in self.scene.lights.iter().zip(&self.light_colors) {
            let to_light = light.position - p;
            let dist = to_light.length();
            let l = to_light / dist;
            let nl = ns.dot(l);
            if nl <= 0.0 {
                continue; // the SPD's rule: no shadow ray
            }
            stats.shadow_rays += 1;
            stats.live_shadow_rays += live as u64;
            let o = self.offset(p, n, l);
            let shadow = Ray { o, d: l };
            let blocked =
                self.bvh
                    .occluded(self.scene, &shadow, 0.0, (light.position - o).length());
            if live {
                RayWays::add(&mut stats.ways.shadow, l);
                if blocked {
                    RayWays::add(&mut stats.ways.shadow_blocked, l);
                }
            }
            if blocked {
                continue;
            }
            let mut c = m.color * (m.kd * nl);
            if m.ks > 0.0 {
                let refl = ns * (2.0 * nl) - l;
                let rv = refl.dot(view);
                if rv > 0.0 {
                    c = c + Vec3::ONE * (m.ks * rv.powf(m.shine));
                }
            }
            color = color + c.mul_elem(*lc);
        }
        if depth < max_depth && (m.ks > 0.0 || m.t > 0.0) {
            stats.reflect_rays += 1;
            let live = live && m.ks > 0.0;
            stats.live_reflect_rays += live as u64;
            let d = r.d - ns * (2.0 * r.d.dot(ns));
            let d = if d.dot(n) > 0.0 {
                d
            } else {
                r.d - n * (2.0 * r.d.dot(n))
            };
            let refl = Ray {
                o: self.offset(p, n, d),
                d: d.normalized(),
            };
            let (c, _) = self.trace_live(&refl, depth + 1, max_depth, live, stats);
            color = color + c * m.ks;
        }
        if depth < max_depth && m.t > 0.0 {
            // Entering through the visible side: from 1 into ior.
            let eta = if h.front { 1.0 / m.ior } else { m.ior };
            let cos_i = -r.d.dot(ns);
            let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
            if k >= 0.0 {
                stats.refract_rays += 1;
                stats.live_refract_rays += live as u64;
                let d = (r.d * eta + ns * (eta * cos_i - k.sqrt())).normalized();
                let refr = Ray {
                    o: self.offset(p, n, d),
                    d,
                };
                let (c, _) = self.trace_live(&refr, depth + 1, max_depth, live, stats);
                color = color + c * m.t;
            }
        }
        (color, Some(id))
    }

    /// Origin of a ray leaving `p` in direction `d`: nudged off the surface
    /// to the side `d` goes.
    fn offset(&self, p: Vec3, n: Vec3, d: Vec3) -> Vec3 {
        if d.dot(n) >= 0.0 {
            p + n * self.eps
        } else {
            p - n * self.eps
        }
    }
}

/// The screen coordinates of sample `(i, j)` of `sw` x `sh` samples in an
/// image of `w` x `h` pixels: the samples span [-1, 1] along the smaller
/// image dimension (NFF: the angle is from the first to the last sample
/// row).
fn screen(w: u32, h: u32, sw: u32, sh: u32, i: u32, j: u32) -> (f64, f64) {
    let span = |i: u32, n: u32| {
        if n <= 1 {
            0.0
        } else {
            2.0 * i as f64 / (n - 1) as f64 - 1.0
        }
    };
    let (ax, ay) = if w >= h {
        (w as f64 / h as f64, 1.0)
    } else {
        (1.0, h as f64 / w as f64)
    };
    (span(i, sw) * ax, -span(j, sh) * ay)
}

/// The eye ray through pixel `(i, j)` of a `w` x `h` image, as
/// [`render`] traces it (without `corners`).
pub fn eye_ray(scene: &Scene, w: u32, h: u32, i: u32, j: u32) -> Ray {
    let (w, h) = (w.max(1), h.max(1));
    let (sx, sy) = screen(w, h, w, h, i, j);
    View::new(scene).ray(sx, sy)
}

/// The 8-bit colour and hit object of the listed pixels of a `w` x `h`
/// image, traced as [`render`] traces them (without `corners`).
pub(crate) fn render_pixels(
    scene: &Scene,
    w: u32,
    h: u32,
    max_depth: u32,
    pixels: &[(u32, u32)],
) -> (Vec<u8>, Vec<u32>) {
    let tracer = Tracer::new(scene);
    let view = View::new(scene);
    let (w, h) = (w.max(1), h.max(1));
    let px: Vec<(Vec3, u32)> = pixels
        .par_iter()
        .map(|&(i, j)| {
            let mut stats = RayStats::default();
            let (sx, sy) = screen(w, h, w, h, i, j);
            let (c, id) = tracer.trace(&view.ray(sx, sy), 1, max_depth, &mut stats);
            (c, id.map_or(NO_HIT, |i| i as u32))
        })
        .collect();
    (
        px.iter()
            .flat_map(|(c, _)| [to8(c.x), to8(c.y), to8(c.z)])
            .collect(),
        px.iter().map(|p| p.1).collect(),
    )
}

/// [`RayWays`] of the rays of every `stride`-th pixel in both directions
/// of a `w` x `h` image (from `stride / 2`), traced as [`render`] traces
/// them to `max_depth`.
pub fn ray_ways(scene: &Scene, w: u32, h: u32, max_depth: u32, stride: u32) -> RayWays {
    let tracer = Tracer::new(scene);
    let view = View::new(scene);
    let (w, h, k) = (w.max(1), h.max(1), stride.max(1));
    let rows: Vec<u32> = (k / 2..h).step_by(k as usize).collect();
    rows.par_iter()
        .map(|&j| {
            let mut stats = RayStats::default();
            for i in (k / 2..w).step_by(k as usize) {
                let (sx, sy) = screen(w, h, w, h, i, j);
                tracer.trace(&view.ray(sx, sy), 1, max_depth, &mut stats);
            }
            stats.ways
        })
        .reduce(RayWays::default, |mut a, b| {
            a += b;
            a
        })
}

/// Render a scene.
pub fn render(scene: &Scene, opt: &Options) -> Image {
    let tracer = Tracer::new(scene);
    let view = View::new(scene);
    let (w, h) = (opt.width.max(1), opt.height.max(1));
    let (sw, sh) = if opt.corners { (w + 1, h + 1) } else { (w, h) };
    let bar = if opt.progress && (sw as u64 * sh as u64) >= 1 << 16 {
        let b = crate::output::progress_bar(sh as u64);
        b.set_style(
            ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} rows, {eta} left")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        b.set_message("tracing");
        b
    } else {
        ProgressBar::hidden()
    };
    let rows: Vec<(Vec<Vec3>, Vec<u32>, RayStats)> = (0..sh)
        .into_par_iter()
        .map(|j| {
            let mut stats = RayStats::default();
            let mut colors = Vec::with_capacity(sw as usize);
            let mut ids = Vec::with_capacity(sw as usize);
            for i in 0..sw {
                let (sx, sy) = screen(w, h, sw, sh, i, j);
                let ray = view.ray(sx, sy);
                stats.eye_rays += 1;
                let (c, id) = tracer.trace(&ray, 1, opt.max_depth, &mut stats);
                if id.is_some() {
                    stats.eye_hit_rays += 1;
                }
                colors.push(c);
                ids.push(id.map_or(NO_HIT, |i| i as u32));
            }
            bar.inc(1);
            (colors, ids, stats)
        })
        .collect();
    bar.finish_and_clear();
    let mut stats = RayStats::default();
    for (_, _, s) in &rows {
        stats += *s;
    }
    let mut rgb = Vec::with_capacity((w * h) as usize);
    let mut hits = Vec::with_capacity((w * h) as usize);
    if opt.corners {
        for j in 0..h as usize {
            for i in 0..w as usize {
                let (a, b) = (&rows[j].0, &rows[j + 1].0);
                rgb.push((a[i] + a[i + 1] + b[i] + b[i + 1]) * 0.25);
                hits.push(rows[j].1[i]);
            }
        }
    } else {
        for (c, id, _) in rows {
            rgb.extend(c);
            hits.extend(id);
        }
    }
    Image {
        width: w,
        height: h,
        rgb,
        hits,
        stats,
    }
}
