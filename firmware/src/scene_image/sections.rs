//! The image's sections, written in order: header, camera, lights,
//! materials, objects by type, polygon vertices, BSP nodes, index lists.
//! Word by word in `docs/scenes.md`.

use crate::bsp::{Bsp, Node};
use crate::scene::{
    AaBox, Cone, Disc, Polygon, PrimType, Rectangle, Scene, SceneError, Shape, Sphere, Triangle,
    Vec3,
};

use super::fit::dequantized;
use super::{
    membership_words, record_words, CompileOptions, Groups, LayoutChoice, NodeFormat, QFormat,
    HEADER_WORDS, LIST_INDEX_BITS, MAGIC, NO_CHILD, Q_MATERIAL, Q_UNIT, VERSION,
};

/// Header words holding the 32-bit section addresses (high word first):
/// camera, lights, materials, objects of each of the paper's 7 types,
/// polygon vertices, nodes, lists; the disc's count and objects after
/// them ([`count_word`], [`objects_word`]).
const A_CAMERA: usize = 16;
const A_LIGHTS: usize = 18;
const A_MATERIALS: usize = 20;
const A_OBJECTS: usize = 22; // 7 pairs
const A_VERTICES: usize = 36;
const A_NODES: usize = 38;
const A_LISTS: usize = 40;
const N_DISCS: usize = 42;
const A_DISCS: usize = 43;

/// The header word of type `t`'s object count.
fn count_word(t: PrimType) -> usize {
    match t {
        PrimType::Disc => N_DISCS,
        t => 9 + t.index(),
    }
}

/// The header word of the address of type `t`'s first object.
fn objects_word(t: PrimType) -> usize {
    match t {
        PrimType::Disc => A_DISCS,
        t => A_OBJECTS + 2 * t.index(),
    }
}

/// The image being written, and the largest rounding error so far.
pub(super) struct Writer {
    pub words: Vec<u16>,
    q: QFormat,
    pub max_err: f64,
}

impl Writer {
    /// An image of one blank header.
    pub fn new(q: QFormat) -> Writer {
        Writer {
            words: vec![0; HEADER_WORDS],
            q,
            max_err: 0.0,
        }
    }
    fn word(&mut self, w: u16) {
        self.words.push(w);
    }
    fn coord(&mut self, x: f64) {
        // `fit` guarantees the range.
        let q = self
            .q
            .quantize(x)
            .unwrap_or(if x < 0.0 { i16::MIN } else { i16::MAX });
        self.max_err = self.max_err.max((self.q.value(q) - x).abs());
        self.words.push(q as u16);
    }
    fn point(&mut self, v: Vec3) {
        self.coord(v.x);
        self.coord(v.y);
        self.coord(v.z);
    }
    fn fixed(&mut self, f: QFormat, x: f64) {
        let q = f
            .quantize(x)
            .unwrap_or(if x < 0.0 { i16::MIN } else { i16::MAX });
        self.words.push(q as u16);
    }
    fn addr(&mut self, at: usize, value: usize) {
        self.words[at] = (value >> 16) as u16;
        self.words[at + 1] = value as u16;
    }
}

/// Header words 0-15: magic, version, fraction bits, layout, node count,
/// root, words per node, and the counts of lights, materials and each
/// type (each checked to fit 16 bits before).
pub(super) fn header(w: &mut Writer, scene: &Scene, g: &Groups, bsp: &Bsp, l: &LayoutChoice) {
    w.words[0] = MAGIC;
    w.words[1] = VERSION;
    w.words[2] = w.q.frac as u16;
    w.words[3] = match l.layout {
        NodeFormat::BitVectors => 0,
        NodeFormat::IndexLists => 1,
    };
    w.words[4] = bsp.nodes.len() as u16;
    w.words[5] = 0; // root node index
    w.words[6] = match l.layout {
        NodeFormat::BitVectors => 4 + l.bv_per_node,
        NodeFormat::IndexLists => 8,
    } as u16;
    w.words[7] = scene.lights.len() as u16;
    w.words[8] = scene.materials.len() as u16;
    for t in PrimType::ALL {
        w.words[count_word(t)] = g.by_type[t.index()].len() as u16;
    }
}

/// The camera: eye, look-at point, unit up vector, tan(angle/2),
/// resolution, background colour.
pub(super) fn camera(w: &mut Writer, scene: &Scene, notes: &mut Vec<String>) {
    let at_camera = w.words.len();
    w.addr(A_CAMERA, at_camera);
    let c = &scene.camera;
    w.point(c.from);
    w.point(c.at);
    let up = c.up.normalized();
    for x in up.to_array() {
        w.fixed(Q_UNIT, x);
    }
    w.fixed(Q_MATERIAL, (c.angle.to_radians() / 2.0).tan());
    if (c.angle.to_radians() / 2.0).tan() >= 8.0 {
        notes.push("camera angle too wide for Q3.12 tan(angle/2): clamped".into());
    }
    w.word(c.resolution.0.min(u16::MAX as u32) as u16);
    w.word(c.resolution.1.min(u16::MAX as u32) as u16);
    for x in scene.background.to_array() {
        w.fixed(Q_MATERIAL, x);
    }
}

/// The lights: position and colour (white shared among the lights when
/// the scene gives none).
pub(super) fn lights(w: &mut Writer, scene: &Scene) {
    let n_lights = scene.lights.len().max(1) as f64;
    let at_lights = w.words.len();
    w.addr(A_LIGHTS, at_lights);
    for l in &scene.lights {
        w.point(l.position);
        for x in l.color.unwrap_or(Vec3::ONE / n_lights.sqrt()).to_array() {
            w.fixed(Q_MATERIAL, x);
        }
    }
}

/// The materials: colour, kd, ks, transmission, index of refraction in
/// Q3.12 and the Phong exponent as an integer.
pub(super) fn materials(w: &mut Writer, scene: &Scene, notes: &mut Vec<String>) {
    let at_materials = w.words.len();
    w.addr(A_MATERIALS, at_materials);
    for m in &scene.materials {
        for x in [m.color.x, m.color.y, m.color.z, m.kd, m.ks, m.t, m.ior] {
            if x.abs() >= 8.0 {
                notes.push(format!("material value {x} is out of Q3.12 range: clamped"));
            }
            w.fixed(Q_MATERIAL, x);
        }
        if m.shine > u16::MAX as f64 {
            notes.push(format!(
                "Phong exponent {} clamped to {}",
                m.shine,
                u16::MAX
            ));
        }
        w.word(m.shine.round().clamp(0.0, u16::MAX as f64) as u16);
    }
}

/// The objects grouped by type, then the polygons' vertices; refuses an
/// object that rounding made degenerate. Returns the words written.
pub(super) fn objects(
    w: &mut Writer,
    scene: &Scene,
    g: &Groups,
    opt: &CompileOptions,
) -> Result<usize, SceneError> {
    let mut polygon_vertices: Vec<Vec3> = Vec::new();
    let mut polygon_fixups = Vec::new();
    let at_objects = w.words.len();
    for t in PrimType::ALL {
        let here = w.words.len();
        w.addr(objects_word(t), here);
        for &i in &g.by_type[t.index()] {
            let o = &scene.objects[i];
            let start = w.words.len();
            if let Some(fixup) = record(w, t, &o.shape, o.material) {
                polygon_fixups.push((fixup, polygon_vertices.len()));
                if let Some(Polygon { v, .. }) = o.shape.as_polygon() {
                    polygon_vertices.extend_from_slice(v);
                }
            }
            debug_assert_eq!(w.words.len() - start, record_words(t));
            // A record that quantizing made degenerate cannot be traced.
            let dq = dequantized(&o.shape, w.q);
            // (Rounding may tilt a rectangle's edges or a polygon's vertices
            // off the plane by a fraction of an LSB: harmless. Shapes in
            // frames of their own keep their shape there.)
            if let Some(why) = dq
                .degeneracy()
                .filter(|_| opt.target_extra_frac == 0)
                .filter(|_| !opt.local_frames || super::fit::local_frame(scene, &o.shape).is_none())
                .filter(|m| !m.contains("perpendicular") && !m.contains("not in the plane"))
            {
                return Err(SceneError {
                    file: scene.source.clone(),
                    line: o.line,
                    col: 0,
                    message: format!(
                        "cannot represent this object in {}: after rounding, {why}",
                        w.q.name()
                    ),
                });
            }
        }
    }
    let at_vertices = w.words.len();
    w.addr(A_VERTICES, at_vertices);
    for (at, first) in polygon_fixups {
        w.addr(at, at_vertices + 3 * first);
    }
    for v in polygon_vertices {
        w.point(v);
    }
    Ok(w.words.len() - at_objects)
}

/// One object's record (`record_words(t)` words); for a polygon, the word
/// its vertices' address goes to once they are placed.
fn record(w: &mut Writer, t: PrimType, shape: &Shape, material: usize) -> Option<usize> {
    let mat = material.min(u16::MAX as usize) as u16;
    match shape {
        Shape::Sphere(Sphere {
            center,
            radius,
            inside,
        }) => {
            w.point(*center);
            w.coord(*radius);
            w.word(mat);
            w.word(*inside as u16);
        }
        Shape::Cone(Cone {
            base,
            base_radius,
            apex,
            apex_radius,
            inside,
            caps,
        }) => {
            w.point(*base);
            w.point(*apex);
            w.coord(*base_radius);
            if t == PrimType::Cone {
                w.coord(*apex_radius);
            }
            w.word(mat);
            w.word(*inside as u16 | (*caps as u16) << 1);
        }
        Shape::Box(AaBox { min, max }) => {
            w.point(*min);
            w.point(*max);
            w.word(mat);
        }
        Shape::Rectangle(Rectangle {
            corner,
            edge1,
            edge2,
        }) => {
            w.point(*corner);
            w.point(*edge1);
            w.point(*edge2);
            w.word(mat);
        }
        Shape::Triangle(Triangle { v, .. }) => {
            v.iter().for_each(|v| w.point(*v));
            w.word(mat);
        }
        Shape::Polygon(Polygon { v, .. }) => {
            w.word(mat);
            w.word(v.len() as u16); // checked before
            let fixup = w.words.len();
            w.word(0);
            w.word(0);
            return Some(fixup);
        }
        Shape::Disc(Disc {
            center,
            normal,
            radius,
        }) => {
            w.point(*center);
            for x in normal.normalized().to_array() {
                w.fixed(Q_UNIT, x);
            }
            w.coord(*radius);
            w.word(mat);
        }
    }
    None
}

/// The BSP nodes in the chosen layout (and, for index lists, the shared
/// list after them). Returns the words written, lists included.
pub(super) fn nodes(w: &mut Writer, bsp: &Bsp, g: &Groups, layout: NodeFormat) -> usize {
    let at_nodes = w.words.len();
    w.addr(A_NODES, at_nodes);
    let slot = |i: u32| g.object_slots[i as usize];
    match layout {
        NodeFormat::BitVectors => {
            for n in &bsp.nodes {
                node_head(w, n);
                for t in &g.present {
                    let members = n
                        .objects
                        .iter()
                        .map(|&i| slot(i))
                        .filter(|(ot, _)| ot == t)
                        .map(|(_, k)| k as usize);
                    w.words
                        .extend(membership_words(g.by_type[t.index()].len(), members));
                }
            }
            w.addr(A_LISTS, 0);
        }
        NodeFormat::IndexLists => {
            let (ranges, list) = index_lists(bsp, &slot);
            for (k, n) in bsp.nodes.iter().enumerate() {
                node_head(w, n);
                let (s, e) = ranges[k];
                w.word((s >> 16) as u16);
                w.word(s as u16);
                w.word(((e - s) >> 16) as u16);
                w.word((e - s) as u16);
            }
            let at_lists = w.words.len();
            w.addr(A_LISTS, at_lists);
            w.words.extend(list);
        }
    }
    w.words.len() - at_nodes
}

/// A node's first four words: axis and depth (bit 15 set for a leaf),
/// split position, the two children.
fn node_head(w: &mut Writer, n: &Node) {
    match n.split {
        Some(s) => {
            w.word(s.axis as u16 | ((n.depth as u16) << 4));
            w.coord(s.position);
            w.word(s.children[0] as u16);
            w.word(s.children[1] as u16);
        }
        None => {
            w.word(0x8000 | ((n.depth as u16) << 4));
            w.word(0);
            w.word(NO_CHILD);
            w.word(NO_CHILD);
        }
    }
}

/// The compact layout's shared list, `(type << 13) | index` per entry,
/// leaf after leaf in node (depth-first) order, and each node's range of
/// it: an inner node's runs from its first leaf's start to its last
/// leaf's end.
fn index_lists(
    bsp: &Bsp,
    slot: &dyn Fn(u32) -> (PrimType, u32),
) -> (Vec<(usize, usize)>, Vec<u16>) {
    let mut ranges = vec![(0usize, 0usize); bsp.nodes.len()];
    let mut list: Vec<u16> = Vec::new();
    for (k, n) in bsp.nodes.iter().enumerate() {
        if n.split.is_none() {
            let start = list.len();
            let mut entries: Vec<u16> = n
                .objects
                .iter()
                .map(|&i| slot(i))
                .map(|(t, k)| ((t.index() as u16) << LIST_INDEX_BITS) | k as u16)
                .collect();
            entries.sort_unstable();
            list.extend(entries);
            ranges[k] = (start, list.len());
        }
    }
    for k in (0..bsp.nodes.len()).rev() {
        if let Some(s) = bsp.nodes[k].split {
            ranges[k] = (
                ranges[s.children[0] as usize].0,
                ranges[s.children[1] as usize].1,
            );
        }
    }
    (ranges, list)
}
