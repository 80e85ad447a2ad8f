//! Reader for Eric Haines' Neutral File Format (NFF), the SPD's format:
//! `v b l f c s p pp #` (see `shared/scenes/NFF-format.txt`).
//!
//! The file is read as a stream of whitespace-separated tokens, each with
//! its line and column, so an entity may be laid out on one line or several
//! (the SPD writes `c` both ways). A `#` starts a comment to the end of the
//! line. Conversions:
//! - `p`/`pp` with 3 vertices become triangles; `p` with 4 vertices that
//!   form a rectangle becomes a [`Rectangle`] (same visible side);
//!   everything else is a [`Polygon`](super::Polygon).
//! - `c` becomes an open [`Cone`] (a cylinder when the radii are
//!   equal); negative radii (both) and negative sphere radii mean "only the
//!   inside is visible".
//! - Objects before the first `f` get the default material (white, Kd 1).

use super::{
    Camera, Cone, Light, Material, Object, Rectangle, Scene, SceneError, Shape, Sphere, Vec3,
};

struct Token<'a> {
    text: &'a str,
    line: usize,
    col: usize,
}

struct Reader<'a> {
    file: &'a str,
    tokens: Vec<Token<'a>>,
    pos: usize,
    last_line: usize,
}

impl<'a> Reader<'a> {
    fn new(text: &'a str, file: &'a str) -> Self {
        let mut tokens = Vec::new();
        let mut last_line = 1;
        for (li, line) in text.lines().enumerate() {
            let line = match line.find('#') {
                Some(i) => &line[..i],
                None => line,
            };
            let mut start = None;
            for (ci, ch) in line
                .char_indices()
                .chain(std::iter::once((line.len(), ' ')))
            {
                if ch.is_whitespace() {
                    if let Some(s) = start.take() {
                        tokens.push(Token {
                            text: &line[s..ci],
                            line: li + 1,
                            col: s + 1,
                        });
                    }
                } else if start.is_none() {
                    start = Some(ci);
                }
            }
            last_line = li + 1;
        }
        Reader {
            file,
            tokens,
            pos: 0,
            last_line,
        }
    }

    fn err_at(&self, line: usize, col: usize, message: String) -> SceneError {
        SceneError {
            file: self.file.to_string(),
            line,
            col,
            message,
        }
    }

    fn peek(&self) -> Option<&Token<'a>> {
        self.tokens.get(self.pos)
    }

    fn next(&mut self, what: &str) -> Result<&Token<'a>, SceneError> {
        match self.tokens.get(self.pos) {
            Some(_) => {
                self.pos += 1;
                Ok(&self.tokens[self.pos - 1])
            }
            None => Err(self.err_at(
                self.last_line,
                0,
                format!("unexpected end of file: expected {what}"),
            )),
        }
    }

    fn number(&mut self, what: &str) -> Result<f64, SceneError> {
        let t = self.next(what)?;
        let (line, col, text) = (t.line, t.col, t.text);
        match text.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            Ok(_) => Err(self.err_at(
                line,
                col,
                format!("expected {what}, found the non-finite number '{text}'"),
            )),
            Err(_) => Err(self.err_at(
                line,
                col,
                format!("expected {what} (a number), found '{text}'"),
            )),
        }
    }

    fn count(&mut self, what: &str) -> Result<usize, SceneError> {
        let t = self.next(what)?;
        let (line, col, text) = (t.line, t.col, t.text);
        match text.parse::<usize>() {
            Ok(n) => Ok(n),
            Err(_) => Err(self.err_at(
                line,
                col,
                format!("expected {what} (a whole number), found '{text}'"),
            )),
        }
    }

    fn vec3(&mut self, what: &str) -> Result<Vec3, SceneError> {
        Ok(Vec3::new(
            self.number(&format!("{what} x"))?,
            self.number(&format!("{what} y"))?,
            self.number(&format!("{what} z"))?,
        ))
    }

    fn keyword(&mut self, kw: &str) -> Result<(), SceneError> {
        let t = self.next(&format!("'{kw}'"))?;
        if t.text == kw {
            Ok(())
        } else {
            let (line, col, text) = (t.line, t.col, t.text.to_string());
            Err(self.err_at(line, col, format!("expected '{kw}', found '{text}'")))
        }
    }
}

/// The entities, each read after its keyword (at `line`, `col`).
impl Reader<'_> {
    /// `v`: the viewpoint.
    fn viewpoint(&mut self, line: usize, col: usize) -> Result<Camera, SceneError> {
        let r = self;
        r.keyword("from")?;
        let from = r.vec3("'from'")?;
        r.keyword("at")?;
        let at = r.vec3("'at'")?;
        r.keyword("up")?;
        let up = r.vec3("'up'")?;
        r.keyword("angle")?;
        let angle = r.number("the view angle in degrees")?;
        r.keyword("hither")?;
        let hither = r.number("the hither distance")?;
        r.keyword("resolution")?;
        let xres = r.count("the x resolution")?;
        let yres = r.count("the y resolution")?;
        if xres == 0 || yres == 0 || xres > 16384 || yres > 16384 {
            return Err(r.err_at(
                line,
                col,
                format!("resolution {xres}x{yres}: each must be between 1 and 16384"),
            ));
        }
        if (at - from).length() == 0.0 {
            return Err(r.err_at(line, col, "viewpoint 'from' and 'at' coincide".into()));
        }
        if (at - from).cross(up).length() == 0.0 {
            return Err(r.err_at(
                line,
                col,
                "viewpoint 'up' is zero or parallel to the view direction".into(),
            ));
        }
        if !(angle > 0.0 && angle < 180.0) {
            return Err(r.err_at(
                line,
                col,
                format!("view angle {angle} must be in (0, 180) degrees"),
            ));
        }
        Ok(Camera {
            from,
            at,
            up,
            angle,
            hither,
            resolution: (xres as u32, yres as u32),
        })
    }

    /// `l`: a light, its colour optional.
    fn light(&mut self, line: usize) -> Result<Light, SceneError> {
        let r = self;
        let position = r.vec3("light position")?;
        // An optional colour: three more numbers on the same line
        // (a keyword there starts the next entity: a whole scene
        // may be written on one line).
        let number = |r: &Reader, k: usize| {
            r.tokens
                .get(r.pos + k)
                .is_some_and(|t| t.line == line && t.text.parse::<f64>().is_ok())
        };
        let color = if number(r, 0) {
            if !(number(r, 1) && number(r, 2)) {
                let t = r.peek().map(|t| (t.line, t.col)).unwrap_or((line, 0));
                return Err(r.err_at(
                    t.0,
                    t.1,
                    "expected a light colour of 3 numbers (R G B) or nothing".into(),
                ));
            }
            Some(r.vec3("light colour")?)
        } else {
            None
        };
        Ok(Light { position, color })
    }

    /// `f`: a material.
    fn material(&mut self, line: usize, col: usize) -> Result<Material, SceneError> {
        let r = self;
        let color = r.vec3("material colour")?;
        let kd = r.number("Kd")?;
        let ks = r.number("Ks")?;
        let shine = r.number("Shine")?;
        let t = r.number("T (transmittance)")?;
        let ior = r.number("index of refraction")?;
        if t > 0.0 && ior <= 0.0 {
            return Err(r.err_at(
                line,
                col,
                format!("index of refraction {ior} must be > 0 for a transmitting material"),
            ));
        }
        if shine < 0.0 {
            return Err(r.err_at(
                line,
                col,
                format!("Phong exponent (Shine) {shine} must be >= 0"),
            ));
        }
        Ok(Material {
            color,
            kd,
            ks,
            shine,
            t,
            ior,
        })
    }

    /// `s`: a sphere (a negative radius: only its inside visible).
    fn sphere(&mut self, line: usize, col: usize) -> Result<Shape, SceneError> {
        let r = self;
        let center = r.vec3("sphere centre")?;
        let radius = r.number("sphere radius")?;
        if radius == 0.0 {
            return Err(r.err_at(line, col, "sphere has radius 0".into()));
        }
        Ok(Shape::from(Sphere {
            center,
            radius: radius.abs(),
            inside: radius < 0.0,
        }))
    }

    /// `c`: a cone or cylinder, open.
    fn cone(&mut self, line: usize, col: usize) -> Result<Shape, SceneError> {
        let r = self;
        let base = r.vec3("cone base point")?;
        let base_radius = r.number("cone base radius")?;
        let apex = r.vec3("cone apex point")?;
        let apex_radius = r.number("cone apex radius")?;
        let inside = base_radius < 0.0 || apex_radius < 0.0;
        if inside && !(base_radius <= 0.0 && apex_radius <= 0.0) {
            return Err(r.err_at(
                line,
                col,
                "cone radii must both be negative (inside visible) or both >= 0".into(),
            ));
        }
        if (apex - base).length() == 0.0 {
            return Err(r.err_at(
                line,
                col,
                "cone/cylinder base and apex are coincident".into(),
            ));
        }
        if base_radius == 0.0 && apex_radius == 0.0 {
            return Err(r.err_at(line, col, "cone/cylinder has radius 0 at both ends".into()));
        }
        Ok(Shape::from(Cone {
            base,
            base_radius: base_radius.abs(),
            apex,
            apex_radius: apex_radius.abs(),
            inside,
            caps: false,
        }))
    }

    /// `p` or `pp` (`patch`: with vertex normals): a polygon, triangle or
    /// rectangle.
    fn polygon(&mut self, patch: bool, line: usize, col: usize) -> Result<Shape, SceneError> {
        let r = self;
        let n = r.count("the number of vertices")?;
        if n < 3 {
            return Err(r.err_at(
                line,
                col,
                format!("polygon with {n} vertices: it needs at least 3"),
            ));
        }
        if n > 1 << 20 {
            return Err(r.err_at(line, col, format!("polygon with {n} vertices is too large")));
        }
        let mut v = Vec::with_capacity(n);
        let mut normals = Vec::new();
        for i in 0..n {
            v.push(r.vec3(&format!("vertex {} of {n}", i + 1))?);
            if patch {
                normals.push(r.vec3(&format!("normal of vertex {} of {n}", i + 1))?);
            }
        }
        let shape = polygon_shape(v, if patch { Some(normals) } else { None });
        // zero area: skipped after reading, with one warning
        if let Some(msg) = shape.degeneracy().filter(|_| shape.zero_area().is_none()) {
            return Err(r.err_at(line, col, msg));
        }
        Ok(shape)
    }
}

/// Parse NFF text; `file` names it in messages. The result is validated.
pub fn parse(text: &str, file: &str) -> Result<Scene, SceneError> {
    let mut r = Reader::new(text, file);
    let mut scene = Scene {
        source: file.to_string(),
        ..Scene::default()
    };
    let mut material: Option<usize> = None;
    let mut seen_view = false;
    while let Some(t) = r.peek() {
        let (line, col) = (t.line, t.col);
        let kw = t.text.to_string();
        r.pos += 1;
        if matches!(kw.as_str(), "s" | "c" | "p" | "pp")
            && scene.objects.len() >= super::MAX_OBJECTS
        {
            return Err(r.err_at(
                line,
                col,
                format!(
                    "more than {} objects: scenes are limited to that (this is the first one past it)",
                    super::MAX_OBJECTS
                ),
            ));
        }
        let mut add = |scene: &mut Scene, shape: Shape| {
            let m = *material.get_or_insert_with(|| {
                scene.materials.push(Material::default());
                scene.lines.materials.push(0);
                scene.materials.len() - 1
            });
            scene.objects.push(Object {
                shape,
                material: m,
                line,
            });
        };
        match kw.as_str() {
            "v" => {
                if seen_view {
                    return Err(r.err_at(line, col, "a second viewpoint 'v': NFF has one".into()));
                }
                seen_view = true;
                scene.lines.camera = line;
                scene.camera = r.viewpoint(line, col)?;
            }
            "b" => scene.background = r.vec3("background colour")?,
            "l" => {
                let light = r.light(line)?;
                scene.lights.push(light);
                scene.lines.lights.push(line);
            }
            "f" => {
                scene.materials.push(r.material(line, col)?);
                scene.lines.materials.push(line);
                material = Some(scene.materials.len() - 1);
            }
            "s" => {
                let shape = r.sphere(line, col)?;
                add(&mut scene, shape);
            }
            "c" => {
                let shape = r.cone(line, col)?;
                add(&mut scene, shape);
            }
            "p" | "pp" => {
                let shape = r.polygon(kw == "pp", line, col)?;
                add(&mut scene, shape);
            }
            _ => {
                return Err(r.err_at(
                    line,
                    col,
                    format!(
                    "unknown entity '{kw}': expected one of v, b, l, f, c, s, p, pp or a # comment"
                ),
                ))
            }
        }
    }
    if !seen_view {
        return Err(SceneError {
            file: file.into(),
            line: 0,
            col: 0,
            message: "no viewpoint ('v' entity)".into(),
        });
    }
    scene.skip_degenerate()?;
    scene.validate()?;
    Ok(scene)
}

/// Triangle, rectangle or general polygon from NFF vertices.
fn polygon_shape(v: Vec<Vec3>, normals: Option<Vec<Vec3>>) -> Shape {
    if v.len() == 4 && normals.is_none() {
        let (e1, e2) = (v[1] - v[0], v[3] - v[0]);
        let scale = e1.length().max(e2.length());
        let closes = (v[0] + e1 + e2 - v[2]).length() <= 1e-9 * scale;
        let square = e1.dot(e2).abs() <= 1e-9 * e1.length() * e2.length();
        if scale > 0.0 && closes && square && e1.cross(e2).length() > 0.0 {
            return Shape::from(Rectangle {
                corner: v[0],
                edge1: e1,
                edge2: e2,
            });
        }
    }
    Shape::polygon(v, normals)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Polygon;

    const HEAD: &str =
        "v\nfrom 0 0 10\nat 0 0 0\nup 0 1 0\nangle 45\nhither 0.01\nresolution 8 8\n";

    #[test]
    fn reads_every_entity() {
        let text = format!(
            "{HEAD}b 0.1 0.2 0.3\nl 1 2 3\nl 4 5 6 0.5 0.5 0.5 # coloured\n\
             f 1 0 0 0.7 0.3 20 0 1\ns 0 0 0 -1\nc 0 0 0 1 0 0 1 1\nc\n0 0 0 -1\n0 1 0 -0.5\n\
             p 3\n0 0 0\n1 0 0\n0 1 0\np 4 0 0 0 2 0 0 2 1 0 0 1 0\np 5 0 0 0 2 0 0 2 2 0 1 1 0 0 2 0\n\
             pp 3\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n"
        );
        let s = parse(&text, "t.nff").unwrap();
        assert_eq!(s.background, Vec3::new(0.1, 0.2, 0.3));
        assert_eq!(s.lights.len(), 2);
        assert_eq!(s.lights[0].color, None);
        assert_eq!(s.lights[1].color, Some(Vec3::new(0.5, 0.5, 0.5)));
        assert_eq!(s.objects.len(), 7);
        assert!(
            matches!(s.objects[0].shape.as_sphere(), Some(Sphere { radius, inside: true, .. }) if *radius == 1.0)
        );
        assert!(
            matches!(s.objects[2].shape.as_cone(), Some(Cone { inside: true, apex_radius, .. }) if *apex_radius == 0.5)
        );
        assert!(s.objects[3].shape.as_triangle().unwrap().normals.is_none());
        assert!(s.objects[4].shape.as_rectangle().is_some());
        assert_eq!(s.objects[5].shape.as_polygon().unwrap().v.len(), 5);
        assert!(s.objects[6].shape.as_triangle().unwrap().normals.is_some());
        assert_eq!(s.objects[6].line, 23);
    }

    #[test]
    fn degenerate_polygons_are_skipped_with_one_warning() {
        // line 8: a good sphere; 9-12: collinear; 13-16: coincident; 17-21: a
        // pp triangle with a zero normal; 21: a good one.
        let text = format!(
            "{HEAD}s 0 0 0 1\np 3\n0 0 0\n1 1 1\n2 2 2\np 3\n1 0 0\n1 0 0\n0 1 0\n\
             pp 3\n0 0 0 0 0 1\n1 0 0 0 0 0\n0 1 0 0 0 1\np 3 0 0 0 1 0 0 0 1 0\n"
        );
        let s = parse(&text, "d.nff").unwrap();
        assert_eq!(s.objects.len(), 2);
        assert_eq!((s.objects[0].line, s.objects[1].line), (8, 21));
        assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
        let w = &s.warnings[0];
        assert_eq!((w.line, w.count, w.feature.as_str()), (9, 3, "degenerate"));
        assert!(
            w.to_string()
                .starts_with("d.nff:9: warning: skipped 3 degenerate polygons"),
            "{w}"
        );
        // Nothing left: refused, naming the first.
        let e = parse(&format!("{HEAD}p 3\n0 0 0\n1 1 1\n2 2 2\n"), "e.nff").unwrap_err();
        assert!(
            e.to_string().starts_with("e.nff:8: nothing to render"),
            "{e}"
        );
        // A scene without degenerate objects has no warning.
        assert!(parse(&format!("{HEAD}s 0 0 0 1\n"), "ok.nff")
            .unwrap()
            .warnings
            .is_empty());
    }

    #[test]
    fn polygons_start_at_a_convex_corner() {
        // An L-shaped hexagon, counter-clockwise seen from +z, listed from
        // its reflex corner (1, 1): the first three vertices would give a
        // normal pointing to -z. Also one with collinear first vertices.
        let text = format!(
            "{HEAD}p 6\n1 1 0\n0 1 0\n0 0 0\n2 0 0\n2 2 0\n1 2 0\n\
             p 5\n0 0 0\n1 0 0\n2 0 0\n2 2 0\n0 2 0\n"
        );
        let s = parse(&text, "l.nff").unwrap();
        assert!(s.warnings.is_empty());
        for o in &s.objects {
            let Some(Polygon { v, .. }) = o.shape.as_polygon() else {
                panic!("{:?}", o.shape)
            };
            let n = (v[1] - v[0]).cross(v[2] - v[0]);
            assert!(n.z > 0.0, "line {}: {v:?}", o.line);
        }
        // The outline is unchanged: the same vertices in the same cyclic order.
        let v = &s.objects[0].shape.as_polygon().unwrap().v;
        let i = v
            .iter()
            .position(|p| *p == Vec3::new(1.0, 1.0, 0.0))
            .unwrap();
        assert_eq!(v[(i + 1) % 6], Vec3::new(0.0, 1.0, 0.0));
        assert_eq!(v.len(), 6);
    }

    #[test]
    fn errors_name_line_and_column() {
        let e = parse(&format!("{HEAD}s 0 0 zero 1\n"), "bad.nff").unwrap_err();
        assert_eq!((e.line, e.col), (8, 7));
        assert!(
            e.to_string()
                .starts_with("bad.nff:8:7: expected sphere centre z"),
            "{e}"
        );
        let e = parse(&format!("{HEAD}s 0 0 0 nan\n"), "bad.nff").unwrap_err();
        assert!(e.to_string().contains("non-finite"), "{e}");
        let e = parse(&format!("{HEAD}p 3\n0 0 0\n1 1 1\n2 2 2\n"), "bad.nff").unwrap_err();
        assert_eq!(e.line, 8);
        assert!(e.message.contains("collinear"), "{e}");
        let e = parse(&format!("{HEAD}c 1 1 1 1 1 1 1 0.5\n"), "bad.nff").unwrap_err();
        assert!(e.message.contains("coincident"), "{e}");
        let e = parse(&format!("{HEAD}q 1\n"), "bad.nff").unwrap_err();
        assert!(e.message.contains("unknown entity 'q'"), "{e}");
        let e = parse(&format!("{HEAD}s 0 0\n"), "bad.nff").unwrap_err();
        assert!(e.message.contains("end of file"), "{e}");
    }
}
