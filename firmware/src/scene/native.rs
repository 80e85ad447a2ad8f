//! The native scene format: TOML, for hand-written scenes. It adds to NFF
//! axis-aligned boxes, rectangles, discs, cylinders and cones with
//! optional end caps, and named materials. See `docs/scenes.md` for the whole format;
//! in short:
//!
//! ```toml
//! background = [0.1, 0.2, 0.4]
//! [camera]
//! from = [0, -8, 3]
//! at = [0, 0, 0]
//! up = [0, 0, 1]
//! angle = 40          # degrees, edge to edge
//! resolution = [256, 256]
//! [[light]]
//! position = [5, -5, 8]
//! color = [0.7, 0.7, 0.7]   # optional
//! [material.red]
//! color = [1, 0.2, 0.2]
//! kd = 0.7
//! ks = 0.3
//! shine = 30
//! [[object]]
//! type = "sphere"
//! material = "red"
//! center = [0, 0, 1]
//! radius = 1
//! ```

use std::collections::BTreeMap;

use serde::Deserialize;
use toml::Spanned;

use super::{
    AaBox, Camera, Cone, Disc, Light, Material, Object, Rectangle, Scene, SceneError, Shape,
    Sphere, Triangle, Vec3,
};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    #[serde(default)]
    background: Option<Vec3>,
    camera: Spanned<CameraDef>,
    #[serde(default)]
    light: Vec<Spanned<LightDef>>,
    #[serde(default)]
    material: BTreeMap<String, Spanned<MaterialDef>>,
    #[serde(default)]
    object: Vec<Spanned<ObjectDef>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraDef {
    from: Vec3,
    at: Vec3,
    up: Vec3,
    angle: f64,
    #[serde(default = "default_hither")]
    hither: f64,
    #[serde(default = "default_resolution")]
    resolution: [u32; 2],
}

fn default_hither() -> f64 {
    1e-3
}
fn default_resolution() -> [u32; 2] {
    [256, 256]
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LightDef {
    position: Vec3,
    #[serde(default)]
    color: Option<Vec3>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialDef {
    color: Vec3,
    #[serde(default = "one")]
    kd: f64,
    #[serde(default)]
    ks: f64,
    #[serde(default)]
    shine: f64,
    #[serde(default)]
    t: f64,
    #[serde(default = "one")]
    ior: f64,
}

fn one() -> f64 {
    1.0
}

/// One `[[object]]` table. Flat, so that serde's errors point at the
/// offending key; which keys each type needs is checked in [`shape_of`].
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ObjectDef {
    #[serde(rename = "type")]
    kind: String,
    material: String,
    center: Option<Vec3>,
    normal: Option<Vec3>,
    radius: Option<f64>,
    base: Option<Vec3>,
    apex: Option<Vec3>,
    base_radius: Option<f64>,
    apex_radius: Option<f64>,
    caps: Option<bool>,
    inside: Option<bool>,
    min: Option<Vec3>,
    max: Option<Vec3>,
    corner: Option<Vec3>,
    edge1: Option<Vec3>,
    edge2: Option<Vec3>,
    vertices: Option<Vec<Vec3>>,
}

const TYPES: &str = "sphere, cylinder, cone, box, rectangle, triangle, polygon, disc";

/// The shape an object table describes, or what is wrong with it.
fn shape_of(o: &ObjectDef) -> Result<Shape, String> {
    let keys: &[(&str, bool)] = &[
        ("center", o.center.is_some()),
        ("normal", o.normal.is_some()),
        ("radius", o.radius.is_some()),
        ("base", o.base.is_some()),
        ("apex", o.apex.is_some()),
        ("base_radius", o.base_radius.is_some()),
        ("apex_radius", o.apex_radius.is_some()),
        ("caps", o.caps.is_some()),
        ("inside", o.inside.is_some()),
        ("min", o.min.is_some()),
        ("max", o.max.is_some()),
        ("corner", o.corner.is_some()),
        ("edge1", o.edge1.is_some()),
        ("edge2", o.edge2.is_some()),
        ("vertices", o.vertices.is_some()),
    ];
    let (required, optional): (&[&str], &[&str]) = match o.kind.as_str() {
        "sphere" => (&["center", "radius"], &["inside"]),
        "cylinder" => (&["base", "apex", "radius"], &["caps", "inside"]),
        "cone" => (
            &["base", "apex", "base_radius", "apex_radius"],
            &["caps", "inside"],
        ),
        "box" => (&["min", "max"], &[]),
        "rectangle" => (&["corner", "edge1", "edge2"], &[]),
        "triangle" | "polygon" => (&["vertices"], &[]),
        "disc" => (&["center", "normal", "radius"], &[]),
        k => {
            return Err(format!(
                "unknown object type '{k}': expected one of {TYPES}"
            ))
        }
    };
    for (k, present) in keys {
        if *present && !required.contains(k) && !optional.contains(k) {
            return Err(format!(
                "a {} takes no '{k}' (it takes {})",
                o.kind,
                required.join(", ")
            ));
        }
        if !*present && required.contains(k) {
            return Err(format!(
                "a {} needs '{k}' (it takes {})",
                o.kind,
                required.join(", ")
            ));
        }
    }
    let (caps, inside) = (o.caps.unwrap_or(false), o.inside.unwrap_or(false));
    let u = |v: Option<Vec3>| v.unwrap_or_default();
    let f = |v: Option<f64>| v.unwrap_or_default();
    Ok(match o.kind.as_str() {
        "sphere" => Shape::from(Sphere {
            center: u(o.center),
            radius: f(o.radius),
            inside,
        }),
        "cylinder" => Shape::from(Cone {
            base: u(o.base),
            base_radius: f(o.radius),
            apex: u(o.apex),
            apex_radius: f(o.radius),
            inside,
            caps,
        }),
        "cone" => Shape::from(Cone {
            base: u(o.base),
            base_radius: f(o.base_radius),
            apex: u(o.apex),
            apex_radius: f(o.apex_radius),
            inside,
            caps,
        }),
        "box" => Shape::from(AaBox {
            min: u(o.min),
            max: u(o.max),
        }),
        "rectangle" => Shape::from(Rectangle {
            corner: u(o.corner),
            edge1: u(o.edge1),
            edge2: u(o.edge2),
        }),
        "disc" => Shape::from(Disc {
            center: u(o.center),
            normal: u(o.normal),
            radius: f(o.radius),
        }),
        kind => {
            let v = o.vertices.clone().unwrap_or_default();
            match (kind, v.len()) {
                ("triangle", 3) | ("polygon", 3) => Shape::from(Triangle {
                    v: [v[0], v[1], v[2]],
                    normals: None,
                }),
                ("triangle", n) => return Err(format!("a triangle needs 3 vertices, found {n}")),
                (_, n) if n < 3 => {
                    return Err(format!("a polygon needs at least 3 vertices, found {n}"))
                }
                _ => Shape::polygon(v, None),
            }
        }
    })
}

/// Line and column (1-based) of a byte offset.
/// Where a TOML error the parser gives no position for (its nesting limit:
/// "recursion limit") most likely is: the first line that nests deepest
/// (dotted keys, tables, arrays and inline tables, outside strings).
/// 1-based; 0 for an empty text.
pub fn deepest_line(text: &str) -> usize {
    let mut best = (0usize, 0usize);
    for (k, line) in text.lines().enumerate() {
        let (mut depth, mut quote) = (0usize, None::<char>);
        for c in line.chars() {
            match (quote, c) {
                (Some(q), c) if c == q => quote = None,
                (Some(_), _) => {}
                (None, '"' | '\'') => quote = Some(c),
                (None, '#') => break,
                (None, '.' | '[' | '{') => depth += 1,
                _ => {}
            }
        }
        if depth > best.0 {
            best = (depth, k + 1);
        }
    }
    best.1
}

fn line_col(text: &str, offset: usize) -> (usize, usize) {
    Lines::of(text).at(offset)
}

/// Where each line of a text starts: 1-based line and column of any byte
/// offset in O(log lines), so locating every object of a large scene
/// stays linear in the file.
struct Lines {
    starts: Vec<usize>,
    len: usize,
}

impl Lines {
    fn of(text: &str) -> Lines {
        let starts = std::iter::once(0)
            .chain(text.match_indices('\n').map(|(i, _)| i + 1))
            .collect();
        Lines {
            starts,
            len: text.len(),
        }
    }

    fn at(&self, offset: usize) -> (usize, usize) {
        let offset = offset.min(self.len);
        let line = self.starts.partition_point(|&s| s <= offset);
        (line, offset - self.starts[line - 1] + 1)
    }
}

/// Parse native TOML text; `file` names it in messages. The result is
/// validated.
pub fn parse(text: &str, file: &str) -> Result<Scene, SceneError> {
    // Objects counted before the document is built (a TOML document takes
    // several times the memory of its objects).
    if let Some((at, _)) = text.match_indices("[[object]]").nth(super::MAX_OBJECTS) {
        let (line, col) = line_col(text, at);
        return Err(SceneError {
            file: file.into(),
            line,
            col,
            message: format!(
                "more than {} objects: scenes are limited to that (this is the first one past it)",
                super::MAX_OBJECTS
            ),
        });
    }
    let def: File = toml::from_str(text).map_err(|e| {
        let (line, col) = e
            .span()
            .map_or((deepest_line(text), 0), |s| line_col(text, s.start));
        SceneError {
            file: file.into(),
            line,
            col,
            message: e.message().trim().replace('\n', " "),
        }
    })?;
    let mut scene = Scene {
        source: file.to_string(),
        ..Scene::default()
    };
    let lines = Lines::of(text);
    scene.lines.camera = lines.at(def.camera.span().start).0;
    let c = def.camera.into_inner();
    scene.camera = Camera {
        from: c.from,
        at: c.at,
        up: c.up,
        angle: c.angle,
        hither: c.hither,
        resolution: (c.resolution[0], c.resolution[1]),
    };
    scene.background = def.background.unwrap_or(Vec3::ZERO);
    scene.lines.lights = def
        .light
        .iter()
        .map(|l| lines.at(l.span().start).0)
        .collect();
    scene.lights = def
        .light
        .into_iter()
        .map(|l| l.into_inner())
        .map(|l| Light {
            position: l.position,
            color: l.color,
        })
        .collect();
    let mut names = BTreeMap::new();
    for (name, m) in def.material {
        names.insert(name, scene.materials.len());
        scene.lines.materials.push(lines.at(m.span().start).0);
        let m = m.into_inner();
        scene.materials.push(Material {
            color: m.color,
            kd: m.kd,
            ks: m.ks,
            shine: m.shine,
            t: m.t,
            ior: m.ior,
        });
    }
    for o in def.object {
        let (line, col) = lines.at(o.span().start);
        let err = |message: String| SceneError {
            file: file.into(),
            line,
            col,
            message,
        };
        let o = o.into_inner();
        let shape = shape_of(&o).map_err(err)?;
        let material = o.material;
        let Some(&m) = names.get(&material) else {
            let known: Vec<&str> = names.keys().map(|s| s.as_str()).collect();
            return Err(err(format!(
                "unknown material '{material}': expected one of [{}]",
                known.join(", ")
            )));
        };
        // zero area: skipped after reading, with one warning
        if let Some(msg) = shape.degeneracy().filter(|_| shape.zero_area().is_none()) {
            return Err(err(msg));
        }
        scene.objects.push(Object {
            shape,
            material: m,
            line,
        });
    }
    scene.skip_degenerate()?;
    scene.validate()?;
    Ok(scene)
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEAD: &str = "[camera]\nfrom = [0, 0, 10]\nat = [0, 0, 0]\nup = [0, 1, 0]\nangle = 45\n\
                        [[light]]\nposition = [1, 2, 3]\n[material.m]\ncolor = [1, 1, 1]\n";

    #[test]
    fn objects_deep_in_a_large_file_are_located() {
        // 3,000 spheres of 6 lines each after HEAD; the 2,500th is bad.
        let mut text = String::from(HEAD);
        for i in 0..3000 {
            let r = if i == 2499 { "-1" } else { "1" };
            text.push_str(&format!(
                "[[object]]\ntype = \"sphere\"\nmaterial = \"m\"\ncenter = [{i}, 0, 0]\nradius = {r}\n\n"
            ));
        }
        let e = parse(&text, "big.toml").unwrap_err();
        let head_lines = HEAD.lines().count();
        assert_eq!((e.line, e.col), (head_lines + 2499 * 6 + 1, 1), "{e}");
    }

    #[test]
    fn reads_every_object_type() {
        let text = format!(
            "{HEAD}[[object]]\ntype = \"sphere\"\nmaterial = \"m\"\ncenter = [0, 0, 0]\nradius = 1\n\
             [[object]]\ntype = \"cylinder\"\nmaterial = \"m\"\nbase = [0, 0, 0]\napex = [0, 1, 0]\nradius = 0.5\ncaps = true\n\
             [[object]]\ntype = \"cone\"\nmaterial = \"m\"\nbase = [0, 0, 0]\nbase_radius = 1\napex = [0, 1, 0]\napex_radius = 0.5\n\
             [[object]]\ntype = \"box\"\nmaterial = \"m\"\nmin = [0, 0, 0]\nmax = [1, 1, 1]\n\
             [[object]]\ntype = \"rectangle\"\nmaterial = \"m\"\ncorner = [0, 0, 0]\nedge1 = [1, 0, 0]\nedge2 = [0, 1, 0]\n\
             [[object]]\ntype = \"triangle\"\nmaterial = \"m\"\nvertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\n\
             [[object]]\ntype = \"polygon\"\nmaterial = \"m\"\nvertices = [[0, 0, 0], [2, 0, 0], [1, 1, 0], [2, 2, 0], [0, 2, 0]]\n"
        );
        let s = parse(&text, "t.toml").unwrap();
        let types: Vec<_> = s
            .objects
            .iter()
            .map(|o| o.shape.prim_type().name())
            .collect();
        assert_eq!(
            types,
            [
                "sphere",
                "cylinder",
                "cone",
                "box",
                "rectangle",
                "triangle",
                "polygon"
            ]
        );
        assert_eq!(s.objects[0].line, 10);
        assert_eq!(s.camera.resolution, (256, 256));
    }

    #[test]
    fn errors_name_line() {
        let e = parse(&format!("{HEAD}[[object]]\ntype = \"sphere\"\nmaterial = \"m\"\ncenter = [0, 0]\nradius = 1\n"), "b.toml")
            .unwrap_err();
        assert_eq!(e.line, 13, "{e}");
        let e = parse(
            &format!("{HEAD}[[object]]\ntype = \"sphere\"\nmaterial = \"m\"\ncenter = [0, 0, 0]\n"),
            "b.toml",
        )
        .unwrap_err();
        assert_eq!(e.line, 10, "{e}");
        assert!(e.message.contains("needs 'radius'"), "{e}");
        let e = parse(&format!("{HEAD}[[object]]\ntype = \"sphere\"\nmaterial = \"x\"\ncenter = [0, 0, 0]\nradius = 1\n"), "b.toml")
            .unwrap_err();
        assert_eq!(e.line, 10, "{e}");
        assert!(e.message.contains("unknown material 'x'"), "{e}");
        let e = parse(&format!("{HEAD}[[object]]\ntype = \"sphere\"\nmaterial = \"m\"\ncenter = [0, 0, 0]\nradius = 0\n"), "b.toml")
            .unwrap_err();
        assert_eq!(e.line, 10, "{e}");
        assert!(e.message.contains("radius"), "{e}");
        let e = parse(
            &format!("{HEAD}[[object]]\ntype = \"blob\"\nmaterial = \"m\"\n"),
            "b.toml",
        )
        .unwrap_err();
        assert!(e.line >= 10, "{e}");
        let e = parse(&format!("{HEAD}[[object]]\ntype = \"box\"\nmaterial = \"m\"\nmin = [0, 0, 0]\nmax = [1, 1, 1]\ncolour = 3\n"), "b.toml")
            .unwrap_err();
        assert!(e.message.contains("colour"), "{e}");
    }
}
