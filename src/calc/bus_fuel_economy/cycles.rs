//! Built-in drive cycles (embedded in the binary) and the interval discretisation of spec §5.1.
//!
//! The three traces are the ones the paper's ADVISOR model would have used: CYC_MANHATTAN,
//! CYC_HWFET and CYC_UDDSHDV ("HDUDDS"), 1 Hz, speed in mph (see `data/bus_fuel_economy/README.md`).

/// Version tag of the embedded cycle data, echoed in every response.
pub const CYCLE_DATA_VERSION: &str = "advisor-2003";

/// 1 mph in m/s (exact by definition of the international mile).
pub const MPH_TO_MPS: f64 = 0.44704;

/// Names of the built-in cycles, in the order of the spec's table (§4).
pub const BUILTIN_NAMES: [&str; 3] = ["manhattan", "hwfet", "hdudds"];

const MANHATTAN_CSV: &str = include_str!("../../../data/bus_fuel_economy/manhattan.csv");
const HWFET_CSV: &str = include_str!("../../../data/bus_fuel_economy/hwfet.csv");
const HDUDDS_CSV: &str = include_str!("../../../data/bus_fuel_economy/hdudds.csv");

/// A speed-vs-time trace in SI units, validated (time strictly increasing, speeds ≥ 0).
#[derive(Debug, Clone)]
pub struct Cycle {
    /// Cycle name (unique within a request).
    pub name: String,
    /// Sample times \[s\].
    pub time_s: Vec<f64>,
    /// Sample speeds [m/s].
    pub speed_mps: Vec<f64>,
    /// Road slope tanθ per sample (`None`: the vehicle's constant grade applies).
    pub grade: Option<Vec<f64>>,
}

impl Cycle {
    /// Duration \[s\].
    #[must_use]
    pub fn duration_s(&self) -> f64 {
        match (self.time_s.first(), self.time_s.last()) {
            (Some(a), Some(b)) => b - a,
            _ => 0.0,
        }
    }

    /// Distance by the interval-mean rule of §5.1, Σ ½(v_j + v_{j+1}) Δt_j \[m\].
    #[must_use]
    pub fn distance_m(&self) -> f64 {
        let mut s = 0.0;
        for j in 1..self.time_s.len() {
            s += 0.5
                * (self.speed_mps[j - 1] + self.speed_mps[j])
                * (self.time_s[j] - self.time_s[j - 1]);
        }
        s
    }

    /// Highest sample speed [m/s].
    #[must_use]
    pub fn max_speed_mps(&self) -> f64 {
        self.speed_mps.iter().copied().fold(0.0, f64::max)
    }

    /// Number of intervals after splitting every interval into `substeps` pieces.
    #[must_use]
    pub fn intervals(&self, substeps: usize) -> usize {
        self.time_s.len().saturating_sub(1) * substeps
    }
}

/// Parse one embedded CSV (`time_s,speed_mph`). `None` if the text is malformed (a build defect;
/// the test suite parses every built-in cycle).
fn parse_csv(name: &str, text: &str) -> Option<Cycle> {
    let mut time_s = Vec::new();
    let mut speed_mps = Vec::new();
    for line in text.lines().skip(1) {
        let line = line.trim();
        if line.is_empty() {
            continue;
        }
        let (t, v) = line.split_once(',')?;
        time_s.push(t.trim().parse::<f64>().ok()?);
        speed_mps.push(v.trim().parse::<f64>().ok()? * MPH_TO_MPS);
    }
    Some(Cycle {
        name: name.to_owned(),
        time_s,
        speed_mps,
        grade: None,
    })
}

/// A built-in cycle by name (`manhattan`, `hwfet`, `hdudds`), `None` for an unknown name. The
/// embedded tables are parsed once per process (parsing all three cost ~0.1 ms per request).
#[must_use]
pub fn builtin(name: &str) -> Option<Cycle> {
    static PARSED: std::sync::OnceLock<[Option<Cycle>; 3]> = std::sync::OnceLock::new();
    let parsed = PARSED.get_or_init(|| {
        [
            parse_csv("manhattan", MANHATTAN_CSV),
            parse_csv("hwfet", HWFET_CSV),
            parse_csv("hdudds", HDUDDS_CSV),
        ]
    });
    let i = match name {
        "manhattan" => 0,
        "hwfet" => 1,
        "hdudds" => 2,
        _ => return None,
    };
    parsed[i].clone()
}

/// One simulation interval of §5.1 (after sub-stepping).
#[derive(Debug, Clone, Copy)]
pub struct Interval {
    /// Start time \[s\].
    pub t0: f64,
    /// Δt_j \[s\].
    pub dt: f64,
    /// Trace speed at the start v_j [m/s].
    pub v0: f64,
    /// Trace speed at the end v_{j+1} [m/s].
    pub v1: f64,
    /// Road slope tanθ over the interval (mean of its end points).
    pub grade: f64,
}

/// Split every interval of `cycle` into `k` equal pieces with linearly interpolated speed (and
/// grade), knob `substeps` of §5.1. `vehicle_grade` applies when the cycle has no grade array.
#[must_use]
pub fn discretise(cycle: &Cycle, k: usize, vehicle_grade: f64) -> Vec<Interval> {
    let k = k.max(1);
    let n = cycle.time_s.len();
    let mut out = Vec::with_capacity(n.saturating_sub(1) * k);
    // Exact conversion for k ≤ 32 (the validated range).
    let kf = k as f64;
    for j in 1..n {
        let (ta, tb) = (cycle.time_s[j - 1], cycle.time_s[j]);
        let (va, vb) = (cycle.speed_mps[j - 1], cycle.speed_mps[j]);
        let (ga, gb) = match &cycle.grade {
            Some(g) => (g[j - 1], g[j]),
            None => (vehicle_grade, vehicle_grade),
        };
        let dt = (tb - ta) / kf;
        for i in 0..k {
            let s0 = i as f64 / kf;
            let s1 = (i + 1) as f64 / kf;
            let lerp = |a: f64, b: f64, s: f64| (b - a).mul_add(s, a);
            let v0 = if i == 0 { va } else { lerp(va, vb, s0) };
            let v1 = if i + 1 == k { vb } else { lerp(va, vb, s1) };
            let g0 = lerp(ga, gb, s0);
            let g1 = lerp(ga, gb, s1);
            out.push(Interval {
                t0: lerp(ta, tb, s0),
                dt,
                v0,
                v1,
                grade: 0.5 * (g0 + g1),
            });
        }
    }
    out
}
