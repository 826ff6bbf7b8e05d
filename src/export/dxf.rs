//! Geometry as DXF (`Accept: image/vnd.dxf`), written with the `dxf` crate (AutoCAD 2000 format,
//! which CAD and CAM programs and `ezdxf` read): one layer per part, `$INSUNITS` from the request's
//! length unit, curves as polylines whose chords stay within [`CHORD_TOLERANCE_MM`] of the curve where
//! the curve is known in closed form (IREFC profiles), and through every computed sample where the
//! answer samples it (coupler curves, workspace outlines, coupling paths).
//!
//! * IREFC (one design): the cam and crown profiles (contact curves), the pitch circles, the
//!   element-centre circle and the rolling elements at the pose φ2 = 0 (element 0 in the cam root),
//!   cam centre at the origin, crown centre at (2e, 0), cage centre at (e, 0); millimetres.
//! * Cognates: the three four-bars at the snapshot pose (links as lines, pivots as circles), the
//!   coupler triangle, and each mechanism's coupler curve per circuit as a polyline; the request's
//!   length unit (unitless in the file: the request names none).
//! * Continuum workspace: per wave the outline of the accepted cells (the platform positions of
//!   the boundary nodes) as polylines and every accepted node as a point; metres.
//! * Spatial coupling: the path of the contact point B in frame 1 (x1, z1) and in frame 2 (x2, z2)
//!   as polylines in the drawing plane; metres.

use dxf::entities::{Circle, Entity, EntityType, Line, LwPolyline, ModelPoint};
use dxf::enums::{AcadVersion, Units};
use dxf::tables::Layer;
use dxf::{Color, Drawing, LwPolylineVertex, Point};
use serde_json::{Value, json};

use crate::calc::irefc::geometry::{Geometry, Wheel};

/// Largest distance between a profile polyline's chord and the exact curve \[mm\]: 0.1 µm, well
/// below wire-EDM and grinding tolerances.
pub const CHORD_TOLERANCE_MM: f64 = 1e-4;
/// Deepest bisection of one parameter interval of a closed-form curve.
const MAX_BISECTIONS: u32 = 20;
/// Samples a coupler curve or a coupling path gets when the DXF request names fewer.
const MIN_CURVE_SAMPLES: u64 = 3600;

/// Why no drawing can be made from an answer.
#[derive(Debug, thiserror::Error)]
pub enum DxfError {
    /// The answer has no geometry to draw (a sweep, an unsolved pose, no accepted node).
    #[error("{0}")]
    Nothing(String),
    /// Writing failed (a bug).
    #[error("DXF writing failed: {0}")]
    Write(String),
}

/// The routes with a drawing.
pub const ROUTES: &[&str] = &[
    "/v1/irefc-stress",
    "/v1/irefc-efficiency",
    "/v1/cognates",
    "/v1/continuum-workspace",
    "/v1/spatial-coupling",
];

/// Whether `route` has a drawing.
#[must_use]
pub fn has_drawing(route: &str) -> bool {
    ROUTES.contains(&route)
}

/// Turn on in `req` the outputs the drawing of `route` needs (and dense enough samples).
pub fn prepare(route: &str, req: &mut Value) {
    let Some(obj) = req.as_object_mut() else {
        return;
    };
    match route {
        "/v1/cognates" => {
            let o = obj.entry("options").or_insert_with(|| json!({}));
            if let Some(o) = o.as_object_mut() {
                o.insert("curves".to_owned(), json!(true));
                let n = o
                    .get("points_per_circuit")
                    .and_then(Value::as_u64)
                    .unwrap_or(0);
                o.insert(
                    "points_per_circuit".to_owned(),
                    json!(n.max(MIN_CURVE_SAMPLES)),
                );
            }
        }
        "/v1/continuum-workspace" => {
            if let Some(w) = obj.get_mut("workspace").and_then(Value::as_object_mut) {
                w.insert("return_nodes".to_owned(), json!(true));
            }
        }
        "/v1/spatial-coupling" => {
            let s = obj
                .entry("sweep")
                .or_insert_with(|| json!({"start_deg": 0, "end_deg": 360}));
            if let Some(s) = s.as_object_mut() {
                let n = s.get("n_points").and_then(Value::as_u64).unwrap_or(0);
                s.insert("n_points".to_owned(), json!(n.max(MIN_CURVE_SAMPLES + 1)));
            }
            let o = obj.entry("outputs").or_insert_with(|| json!({}));
            if let Some(o) = o.as_object_mut() {
                for k in ["series", "relative_1", "relative_2"] {
                    o.insert(k.to_owned(), json!(true));
                }
                o.insert("decimate".to_owned(), json!(1));
            }
        }
        _ => {}
    }
}

/// A drawing under construction.
struct Sheet {
    d: Drawing,
}

impl Sheet {
    fn new(units: Units) -> Self {
        let mut d = Drawing::new();
        d.header.version = AcadVersion::R2000;
        d.header.default_drawing_units = units;
        Self { d }
    }

    fn layer(&mut self, name: &str, color: u8) {
        let mut l = Layer::default();
        name.clone_into(&mut l.name);
        l.color = Color::from_index(color);
        self.d.add_layer(l);
    }

    fn add(&mut self, layer: &str, e: EntityType) {
        let mut e = Entity::new(e);
        layer.clone_into(&mut e.common.layer);
        self.d.add_entity(e);
    }

    fn line(&mut self, layer: &str, a: [f64; 2], b: [f64; 2]) {
        self.add(
            layer,
            EntityType::Line(Line::new(
                Point::new(a[0], a[1], 0.0),
                Point::new(b[0], b[1], 0.0),
            )),
        );
    }

    fn circle(&mut self, layer: &str, c: [f64; 2], r: f64) {
        if r > 0.0 && r.is_finite() {
            self.add(
                layer,
                EntityType::Circle(Circle::new(Point::new(c[0], c[1], 0.0), r)),
            );
        }
    }

    fn point(&mut self, layer: &str, p: [f64; 2]) {
        self.add(
            layer,
            EntityType::ModelPoint(ModelPoint::new(Point::new(p[0], p[1], 0.0))),
        );
    }

    fn polyline(&mut self, layer: &str, pts: &[[f64; 2]], closed: bool) {
        if pts.len() < 2 {
            return;
        }
        let mut p = LwPolyline {
            vertices: pts
                .iter()
                .map(|q| LwPolylineVertex {
                    x: q[0],
                    y: q[1],
                    ..Default::default()
                })
                .collect(),
            ..Default::default()
        };
        p.set_is_closed(closed);
        self.add(layer, EntityType::LwPolyline(p));
    }

    fn finish(self) -> Result<Vec<u8>, DxfError> {
        let mut out = Vec::new();
        self.d
            .save(&mut out)
            .map_err(|e| DxfError::Write(e.to_string()))?;
        Ok(out)
    }
}

/// The DXF drawing of `answer` (to `request`) at `route`.
///
/// # Errors
/// [`DxfError::Nothing`] when the answer holds no geometry to draw.
pub fn render(route: &str, request: &Value, answer: &Value) -> Result<Vec<u8>, DxfError> {
    match route {
        "/v1/irefc-stress" | "/v1/irefc-efficiency" => irefc(request, answer),
        "/v1/cognates" => cognates(answer),
        "/v1/continuum-workspace" => workspace(answer),
        "/v1/spatial-coupling" => coupling(answer),
        _ => Err(DxfError::Nothing(format!(
            "{route} has no geometry to draw"
        ))),
    }
}

fn num(v: &Value, key: &str) -> Option<f64> {
    v.get(key).and_then(Value::as_f64).filter(|x| x.is_finite())
}

fn xy(v: &Value) -> Option<[f64; 2]> {
    Some([v.get(0)?.as_f64()?, v.get(1)?.as_f64()?])
}

/// A closed curve `f(t)`, t ∈ [0, 2π), as vertices: `n0` equal steps, each bisected until the
/// chord's midpoint lies within `tol` of the curve's midpoint (and its quarter points too).
#[must_use]
pub fn adaptive_closed(f: &dyn Fn(f64) -> [f64; 2], n0: usize, tol: f64) -> Vec<[f64; 2]> {
    /// One curve and its tolerance; `split` bisects one parameter interval.
    struct Curve<'a> {
        f: &'a dyn Fn(f64) -> [f64; 2],
        tol: f64,
    }
    impl Curve<'_> {
        /// Largest distance of the curve's quarter points from the chord's.
        fn deviation(&self, t0: f64, t1: f64, a: [f64; 2], b: [f64; 2]) -> f64 {
            [0.25, 0.5, 0.75]
                .iter()
                .map(|s| {
                    let p = (self.f)(t0 + s * (t1 - t0));
                    let q = [a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])];
                    (p[0] - q[0]).hypot(p[1] - q[1])
                })
                .fold(0.0, f64::max)
        }

        fn split(
            &self,
            (t0, t1): (f64, f64),
            (a, b): ([f64; 2], [f64; 2]),
            depth: u32,
            out: &mut Vec<[f64; 2]>,
        ) {
            if depth < MAX_BISECTIONS && self.deviation(t0, t1, a, b) > self.tol {
                let tm = 0.5 * (t0 + t1);
                let m = (self.f)(tm);
                self.split((t0, tm), (a, m), depth + 1, out);
                self.split((tm, t1), (m, b), depth + 1, out);
            } else {
                out.push(a);
            }
        }
    }
    let curve = Curve { f, tol };
    let n0 = n0.max(8);
    let step = std::f64::consts::TAU / n0 as f64;
    let mut out = Vec::new();
    for i in 0..n0 {
        let (t0, t1) = (step * i as f64, step * (i + 1) as f64);
        curve.split((t0, t1), (f(t0), f(t1)), 0, &mut out);
    }
    out
}

/// The gear parameters (r2 [mm], Z2, χ, rb [mm]) of a single-design request.
fn irefc_params(request: &Value) -> Option<(f64, u32, f64, f64)> {
    Some((
        num(request, "r2_mm")?,
        u32::try_from(request.get("Z2")?.as_u64()?).ok()?,
        num(request, "chi")?,
        num(request, "rb_mm")?,
    ))
}

/// Cam and crown profiles, pitch circles, cage and rolling elements at the pose φ2 = 0.
fn irefc(request: &Value, answer: &Value) -> Result<Vec<u8>, DxfError> {
    if answer.get("mode").and_then(Value::as_str) == Some("sweep") {
        return Err(DxfError::Nothing(
            "a design sweep has no single geometry; request mode `single` for one design".into(),
        ));
    }
    let (r2, z2, chi, rb) = irefc_params(request)
        .ok_or_else(|| DxfError::Nothing("the request names no single gear design".into()))?;
    // Every formula is homogeneous in length, so the geometry in millimetres is in millimetres.
    let g = Geometry::new_unchecked(r2, z2, chi, rb);
    let mut s = Sheet::new(Units::Millimeters);
    for (name, color) in [
        ("CAM_PROFILE", 1),
        ("CROWN_PROFILE", 5),
        ("PITCH_CIRCLES", 8),
        ("CAGE", 3),
        ("ROLLING_ELEMENTS", 2),
        ("CENTRES", 7),
    ] {
        s.layer(name, color);
    }
    let n0 = 16 * z2 as usize;
    let cam = adaptive_closed(
        &|t| g.profile_point(Wheel::Cam, t).contact,
        n0,
        CHORD_TOLERANCE_MM,
    );
    s.polyline("CAM_PROFILE", &cam, true);
    // The crown's own frame turned by π and moved to its centre at (2e, 0): the pitch points of
    // both wheels then coincide at (−r1, 0) and the element at φ2 = 0 is the same in both frames.
    let crown = adaptive_closed(
        &|t| {
            let p = g.profile_point(Wheel::Crown, t).contact;
            [2.0 * g.e - p[0], -p[1]]
        },
        n0,
        CHORD_TOLERANCE_MM,
    );
    s.polyline("CROWN_PROFILE", &crown, true);
    let cage = [g.e, 0.0];
    s.circle("PITCH_CIRCLES", [0.0, 0.0], g.r1);
    s.circle("PITCH_CIRCLES", cage, g.r2);
    s.circle("PITCH_CIRCLES", [2.0 * g.e, 0.0], g.r3);
    s.circle("CAGE", cage, g.rc);
    for c in [[0.0, 0.0], cage, [2.0 * g.e, 0.0]] {
        s.point("CENTRES", c);
    }
    for c in element_centres(&g) {
        s.circle("ROLLING_ELEMENTS", c, g.rb);
    }
    s.finish()
}

/// Rolling element centres at the pose φ2 = 0, in the cam frame \[length of `g`\]: element k at
/// φ_k = 2πk/Z2 from the ray cage centre → pitch point.
#[must_use]
pub fn element_centres(g: &Geometry) -> Vec<[f64; 2]> {
    (0..g.z2)
        .map(|k| {
            let phi = std::f64::consts::TAU * f64::from(k) / g.z2f;
            [g.e - g.rc * phi.cos(), -g.rc * phi.sin()]
        })
        .collect()
}

fn cognates(answer: &Value) -> Result<Vec<u8>, DxfError> {
    let mechs = answer
        .get("mechanisms")
        .and_then(Value::as_array)
        .ok_or_else(|| DxfError::Nothing("the answer has no mechanisms".into()))?;
    let mut s = Sheet::new(Units::Unitless);
    s.layer("GROUND_PIVOTS", 7);
    let mut drawn = false;
    for (m_index, m) in mechs.iter().enumerate() {
        let id = m
            .get("id")
            .and_then(Value::as_str)
            .unwrap_or("mechanism")
            .to_uppercase();
        let links = format!("{id}_LINKS");
        let curve = format!("{id}_COUPLER_CURVE");
        // Colours 1, 3, 5: red, green, blue per mechanism.
        let color = u8::try_from(1 + 2 * (m_index % 3)).unwrap_or(1);
        s.layer(&links, color);
        s.layer(&curve, color);
        if let Some(j) = m.pointer("/snapshot/joints") {
            let p = |k: &str| j.get(k).and_then(xy);
            if let (Some(a), Some(b), Some(c), Some(d), Some(pp)) = (
                p("input_pivot"),
                p("crank_joint"),
                p("rocker_joint"),
                p("output_pivot"),
                p("P"),
            ) {
                s.line(&links, a, b);
                s.line(&links, b, c);
                s.line(&links, c, d);
                s.line(&links, b, pp);
                s.line(&links, c, pp);
                s.line("GROUND_PIVOTS", a, d);
                drawn = true;
            }
        }
        for k in ["input_pivot", "output_pivot"] {
            if let Some(q) = m.get(k).and_then(xy) {
                let scale = num(&m["links"], "ground").unwrap_or(1.0).abs();
                s.circle("GROUND_PIVOTS", q, 0.02 * scale);
                s.point("GROUND_PIVOTS", q);
            }
        }
        for c in m
            .get("curves")
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
        {
            let pts: Vec<[f64; 2]> = c
                .get("points")
                .and_then(Value::as_array)
                .into_iter()
                .flatten()
                .filter_map(xy)
                .collect();
            let closed = c.get("closed").and_then(Value::as_bool).unwrap_or(false);
            s.polyline(&curve, &pts, closed);
            drawn |= pts.len() >= 2;
        }
    }
    if !drawn {
        return Err(DxfError::Nothing(
            "the answer has no solved pose and no coupler curve".into(),
        ));
    }
    s.finish()
}

/// The boundary of the union of accepted cells of a `n1 × n2` node grid, as chains of node
/// indices (closed chains end at their start).
#[must_use]
pub fn cell_outline(ok: &[bool], n1: usize, n2: usize) -> Vec<Vec<usize>> {
    let idx = |i: usize, j: usize| i * n2 + j;
    let cell = |i: usize, j: usize| {
        i + 1 < n1
            && j + 1 < n2
            && [idx(i, j), idx(i + 1, j), idx(i, j + 1), idx(i + 1, j + 1)]
                .iter()
                .all(|&k| ok.get(k).copied().unwrap_or(false))
    };
    let cell_at = |i: isize, j: isize| -> bool {
        usize::try_from(i)
            .ok()
            .zip(usize::try_from(j).ok())
            .is_some_and(|(i, j)| cell(i, j))
    };
    // Boundary edges: a cell side whose neighbour across it is not a cell.
    let mut edges: Vec<(usize, usize)> = Vec::new();
    for i in 0..n1.saturating_sub(1) {
        for j in 0..n2.saturating_sub(1) {
            if !cell(i, j) {
                continue;
            }
            let (ii, jj) = (i as isize, j as isize);
            if !cell_at(ii - 1, jj) {
                edges.push((idx(i, j), idx(i, j + 1)));
            }
            if !cell_at(ii + 1, jj) {
                edges.push((idx(i + 1, j), idx(i + 1, j + 1)));
            }
            if !cell_at(ii, jj - 1) {
                edges.push((idx(i, j), idx(i + 1, j)));
            }
            if !cell_at(ii, jj + 1) {
                edges.push((idx(i, j + 1), idx(i + 1, j + 1)));
            }
        }
    }
    let mut used = vec![false; edges.len()];
    let mut at: std::collections::HashMap<usize, Vec<usize>> = std::collections::HashMap::new();
    for (e, &(a, b)) in edges.iter().enumerate() {
        at.entry(a).or_default().push(e);
        at.entry(b).or_default().push(e);
    }
    let mut chains = Vec::new();
    for start in 0..edges.len() {
        if used[start] {
            continue;
        }
        used[start] = true;
        let (a, mut cur) = edges[start];
        let mut chain = vec![a, cur];
        while let Some(&e) = at.get(&cur).and_then(|es| es.iter().find(|&&e| !used[e])) {
            used[e] = true;
            let (x, y) = edges[e];
            cur = if x == cur { y } else { x };
            chain.push(cur);
            if cur == a {
                break;
            }
        }
        chains.push(chain);
    }
    chains
}

fn workspace(answer: &Value) -> Result<Vec<u8>, DxfError> {
    let n1 = answer
        .pointer("/grid/lambda1_m")
        .and_then(Value::as_array)
        .map_or(0, Vec::len);
    let n2 = answer
        .pointer("/grid/lambda2_m")
        .and_then(Value::as_array)
        .map_or(0, Vec::len);
    let mut waves: Vec<&Value> = Vec::new();
    waves.extend(answer.get("nodes"));
    for key in ["other_waves", "waves"] {
        for w in answer
            .get(key)
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
        {
            waves.extend(w.get("nodes"));
        }
    }
    let mut s = Sheet::new(Units::Meters);
    let mut drawn = false;
    for (w, nodes) in waves.iter().enumerate() {
        let status = nodes.get("status").and_then(Value::as_array);
        let px = nodes.get("px_m").and_then(Value::as_array);
        let py = nodes.get("py_m").and_then(Value::as_array);
        let (Some(status), Some(px), Some(py)) = (status, px, py) else {
            continue;
        };
        let pos: Vec<Option<[f64; 2]>> = (0..status.len())
            .map(|k| {
                let ok = status[k].as_str() == Some("ok");
                let p = [px.get(k)?.as_f64()?, py.get(k)?.as_f64()?];
                ok.then_some(p)
            })
            .collect();
        let outline = format!("WAVE_{w}_OUTLINE");
        let points = format!("WAVE_{w}_NODES");
        let color = u8::try_from(1 + w % 6).unwrap_or(1);
        s.layer(&outline, color);
        s.layer(&points, color);
        for p in pos.iter().flatten() {
            s.point(&points, *p);
            drawn = true;
        }
        if n1 * n2 == pos.len() {
            let ok: Vec<bool> = pos.iter().map(Option::is_some).collect();
            for chain in cell_outline(&ok, n1, n2) {
                let closed = chain.len() > 2 && chain.first() == chain.last();
                let mut pts: Vec<[f64; 2]> = chain.iter().filter_map(|&k| pos[k]).collect();
                if closed {
                    pts.pop();
                }
                s.polyline(&outline, &pts, closed);
            }
        }
    }
    if !drawn {
        return Err(DxfError::Nothing(
            "the answer has no accepted workspace node (mode `workspace` draws the nodes)".into(),
        ));
    }
    s.finish()
}

fn coupling(answer: &Value) -> Result<Vec<u8>, DxfError> {
    let series = answer
        .get("series")
        .and_then(Value::as_array)
        .ok_or_else(|| DxfError::Nothing("the answer has no series".into()))?;
    let path = |frame: &str, x: &str, z: &str| -> Vec<[f64; 2]> {
        series
            .iter()
            .filter_map(|r| {
                let f = r.get(frame)?;
                Some([f.get(x)?.as_f64()?, f.get(z)?.as_f64()?])
            })
            .collect()
    };
    let p1 = path("relative_1", "x1B_m", "z1B_m");
    let p2 = path("relative_2", "x2B_m", "z2B_m");
    if p1.len() < 2 && p2.len() < 2 {
        return Err(DxfError::Nothing(
            "the answer has no path of B (`outputs.relative_1`, `outputs.relative_2`)".into(),
        ));
    }
    let mut s = Sheet::new(Units::Meters);
    s.layer("PATH_B_FRAME_1", 1);
    s.layer("PATH_B_FRAME_2", 5);
    s.polyline("PATH_B_FRAME_1", &p1, false);
    s.polyline("PATH_B_FRAME_2", &p2, false);
    s.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outline_of_a_full_grid_is_its_border() {
        let ok = vec![true; 9];
        let chains = cell_outline(&ok, 3, 3);
        assert_eq!(chains.len(), 1);
        // 8 border nodes, closed: 9 entries.
        assert_eq!(chains[0].len(), 9);
        assert_eq!(chains[0].first(), chains[0].last());
        assert!(!chains[0].contains(&4), "the centre node is inside");
    }

    #[test]
    fn adaptive_circle_meets_its_tolerance() {
        let r = 10.0;
        let pts = adaptive_closed(&|t| [r * t.cos(), r * t.sin()], 8, 1e-4);
        // Sagitta r(1 − cos(Δ/2)) of the largest step stays within the tolerance.
        let n = pts.len();
        for k in 0..n {
            let (a, b) = (pts[k], pts[(k + 1) % n]);
            let m = [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
            assert!(r - m[0].hypot(m[1]) <= 1e-4 + 1e-12);
        }
    }
}
