//! Workspace metrics over the accepted nodes of one wave (spec 4.8): cells, signed and folded cell
//! areas, and the area of the union of the cell polygons by rasterisation.

// Raster and shoelace arithmetic in plain form; without a target FMA unit `mul_add` is a libm call.

/// Pixel edge of the union raster as a fraction of `L_ref` (spec 4.8 asks for <= L_ref/250; the
/// finer pixel keeps the rasterisation error well under the 3 % validation tolerance).
const PIXEL_FRACTION: f64 = 1.0 / 1000.0;
/// Largest raster (pixels); the pixel grows beyond `PIXEL_FRACTION L_ref` only for workspaces
/// spanning more than 4 L_ref x 4 L_ref or so.
const MAX_PIXELS: f64 = 16.0e6;

/// One cell: the 4 mapped corner positions in grid order (i,j), (i+1,j), (i+1,j+1), (i,j+1).
pub type Quad = [[f64; 2]; 4];

/// Signed shoelace area of a quad.
#[must_use]
pub fn signed_area(q: &Quad) -> f64 {
    let mut a = 0.0;
    for k in 0..4 {
        let p = q[k];
        let r = q[(k + 1) % 4];
        a += p[0] * r[1] - r[0] * p[1];
    }
    0.5 * a
}

/// Area of the union of the quads (even-odd fill per quad, union over quads), by rasterisation
/// with pixels of at most `PIXEL_FRACTION * l_ref` (coarser only past `MAX_PIXELS`).
#[must_use]
pub fn union_area(quads: &[Quad], l_ref: f64) -> f64 {
    if quads.is_empty() {
        return 0.0;
    }
    let (mut xmin, mut ymin, mut xmax, mut ymax) = (
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    );
    for q in quads {
        for p in q {
            xmin = xmin.min(p[0]);
            xmax = xmax.max(p[0]);
            ymin = ymin.min(p[1]);
            ymax = ymax.max(p[1]);
        }
    }
    if !(xmax > xmin && ymax > ymin && (xmax - xmin + ymax - ymin).is_finite()) {
        return 0.0;
    }
    let mut px = PIXEL_FRACTION * l_ref;
    let cells = (xmax - xmin) * (ymax - ymin) / (px * px);
    if cells > MAX_PIXELS {
        px *= (cells / MAX_PIXELS).sqrt();
    }
    // Both counts are bounded by sqrt(MAX_PIXELS) * (aspect) and finite here; +2 guards the edges.
    let nx = ((xmax - xmin) / px).ceil() as usize + 2;
    let ny = ((ymax - ymin) / px).ceil() as usize + 2;
    if nx.saturating_mul(ny) > 4 * MAX_PIXELS as usize {
        return 0.0;
    }
    let words = nx.div_ceil(64);
    let mut bits = vec![0u64; words * ny];
    let mut xs: Vec<f64> = Vec::with_capacity(4);
    for q in quads {
        let qy0 = q.iter().fold(f64::INFINITY, |m, p| m.min(p[1]));
        let qy1 = q.iter().fold(f64::NEG_INFINITY, |m, p| m.max(p[1]));
        // Pixel rows whose centre y = ymin + (r + 0.5) px lies in [qy0, qy1].
        let r0 = ((qy0 - ymin) / px - 0.5).ceil().max(0.0) as usize;
        let r1 = (((qy1 - ymin) / px - 0.5).floor().max(-1.0) + 1.0) as usize;
        for r in r0..r1.min(ny) {
            let y = ymin + (r as f64 + 0.5) * px;
            xs.clear();
            for k in 0..4 {
                let a = q[k];
                let b = q[(k + 1) % 4];
                if (a[1] <= y) != (b[1] <= y) {
                    xs.push(a[0] + (y - a[1]) * (b[0] - a[0]) / (b[1] - a[1]));
                }
            }
            xs.sort_by(f64::total_cmp);
            for pair in xs.chunks_exact(2) {
                // Pixel columns whose centre x lies in [pair[0], pair[1]).
                let c0 = ((pair[0] - xmin) / px - 0.5).ceil().max(0.0) as usize;
                let c1 = (((pair[1] - xmin) / px - 0.5).ceil().max(0.0) as usize).min(nx);
                for c in c0..c1 {
                    bits[r * words + c / 64] |= 1u64 << (c % 64);
                }
            }
        }
    }
    let count: u64 = bits.iter().map(|w| u64::from(w.count_ones())).sum();
    count as f64 * px * px
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn union_of_overlapping_squares() {
        let sq =
            |x: f64, y: f64| -> Quad { [[x, y], [x + 1.0, y], [x + 1.0, y + 1.0], [x, y + 1.0]] };
        let a = union_area(&[sq(0.0, 0.0), sq(0.5, 0.0)], 10.0);
        assert!((a - 1.5).abs() < 5e-3, "{a}");
        assert!((signed_area(&sq(0.0, 0.0)) - 1.0).abs() < 1e-15);
        // A folded (bow-tie) quad: two triangles of area 0.25 each.
        let bow: Quad = [[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]];
        let b = union_area(&[bow], 10.0);
        assert!((b - 0.5).abs() < 5e-3, "{b}");
    }
}
