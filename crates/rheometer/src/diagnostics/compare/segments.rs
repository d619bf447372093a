//! Systematic segments: contiguous ranges of `s` where the pooled residual keeps one sign and
//! stands significantly above the noise.
//!
//! 1. **Stations.** The measurement positions of all experiments are pooled and clustered:
//!    positions closer than half the median measurement spacing form one station (with shared
//!    positions, as in the shipped data sets, a station is one position measured in every
//!    experiment).
//! 2. **Station mean.** At each station the mean residual `b_j` of its `m_j` residuals, with the
//!    standard error `se_j = max(σ, sd_j)/√m_j` (`σ` the noise level, `sd_j` the sample standard
//!    deviation at the station when `m_j ≥ 5`, so locally larger noise is not mistaken for a
//!    systematic effect).
//! 3. **Candidates.** Stations with `|b_j|/se_j ≥ z_station` are marked with the sign of `b_j`;
//!    runs of marked stations of one sign form a candidate, bridging single unmarked stations
//!    whose mean has the same sign.
//! 4. **Acceptance.** A candidate is reported if the mean `X` of all its residuals has
//!    `|X|/SE ≥ z_segment` (`SE² = Σ m_j² se_j² / (Σ m_j)²`) and `|X| ≥ min_effect`.
//!    Before that, a candidate is split where its level changes (binary segmentation: the split
//!    into two parts of at least 2 stations whose means differ most, if by at least
//!    `z_segment` standard errors; recursively), so "11 % near the nozzle, 4 % further down"
//!    is reported as two segments rather than one average.
//!    For each experiment the mean of its residuals in the segment is kept, and the experiments
//!    with the same sign (and with `|mean| ≥ 2σ/√n_k`) are counted.

use serde::{Deserialize, Serialize};

/// Thresholds of the segment search.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SegmentOptions {
    /// Marking threshold of a station, in standard errors (default 2).
    pub z_station: f64,
    /// Acceptance threshold of a segment, in standard errors (default 4: with a few dozen
    /// stations a false alarm from white noise is rare).
    pub z_segment: f64,
    /// Smallest reported size of a systematic residual, relative (default 0.005 = 0.5 %).
    pub min_effect: f64,
}

impl Default for SegmentOptions {
    fn default() -> Self {
        SegmentOptions {
            z_station: 2.0,
            z_segment: 4.0,
            min_effect: 0.005,
        }
    }
}

/// The pooled residual at one station.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Station {
    /// Mean position of the station (m).
    pub position_m: f64,
    /// Number of residuals `m_j`.
    pub count: usize,
    /// Mean relative residual `b_j` \[-\].
    pub mean: f64,
    /// Standard error `se_j` of the mean \[-\].
    pub std_error: f64,
}

/// A contiguous range of `s` with a significant residual of one sign.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Segment {
    /// First station position (m).
    pub start_m: f64,
    /// Last station position (m).
    pub end_m: f64,
    /// Number of stations.
    pub stations: usize,
    /// Number of residuals in the segment.
    pub points: usize,
    /// Mean relative residual `X = mean (d_model − d_meas)/d_meas` \[-\]; `> 0`: model too thick.
    pub mean: f64,
    /// Standard error of `X` from the noise level \[-\].
    pub std_error: f64,
    /// `X / std_error`.
    pub z: f64,
    /// Standard deviation of the per-experiment means across experiments \[-\] (0 for one).
    pub spread: f64,
    /// Per experiment with points in the segment: (experiment index, mean residual there).
    pub per_experiment: Vec<(usize, f64)>,
    /// Experiments whose mean has the sign of `X`.
    pub same_sign: usize,
    /// Experiments whose mean has the sign of `X` and `|mean| ≥ 2σ/√n_k`.
    pub significant: usize,
}

impl Segment {
    /// `"thick"` if the model is above the measurement, else `"thin"`.
    pub fn direction(&self) -> &'static str {
        if self.mean > 0.0 {
            "thick"
        } else {
            "thin"
        }
    }
}

/// One residual with its position and experiment.
#[derive(Debug, Clone, Copy)]
struct Point {
    s: f64,
    r: f64,
    k: usize,
}

/// Clusters the pooled positions into stations; returns the stations and, per station, the
/// pooled points.
fn stations_of(experiments: &[(Vec<f64>, Vec<f64>)], sigma: f64) -> Vec<(Station, Vec<Point>)> {
    let mut spacings: Vec<f64> = experiments
        .iter()
        .flat_map(|(s, _)| s.windows(2).map(|w| w[1] - w[0]))
        .filter(|h| *h > 0.0)
        .collect();
    let tol = 0.5 * crate::data::statistics::median(&mut spacings);
    let tol = if tol.is_finite() { tol } else { 0.0 };
    let mut pts: Vec<Point> = experiments
        .iter()
        .enumerate()
        .flat_map(|(k, (s, r))| {
            s.iter()
                .zip(r)
                .filter(|(s, r)| s.is_finite() && r.is_finite())
                .map(move |(&s, &r)| Point { s, r, k })
        })
        .collect();
    pts.sort_by(|a, b| a.s.total_cmp(&b.s));
    let mut groups: Vec<Vec<Point>> = Vec::new();
    for p in pts {
        match groups.last_mut() {
            Some(g) if p.s - g[0].s <= tol => g.push(p),
            _ => groups.push(vec![p]),
        }
    }
    groups
        .into_iter()
        .map(|g| {
            let m = g.len() as f64;
            let mean = g.iter().map(|p| p.r).sum::<f64>() / m;
            let sd = if g.len() >= 5 {
                (g.iter().map(|p| (p.r - mean).powi(2)).sum::<f64>() / (m - 1.0)).sqrt()
            } else {
                0.0
            };
            let st = Station {
                position_m: g.iter().map(|p| p.s).sum::<f64>() / m,
                count: g.len(),
                mean,
                std_error: sigma.max(sd) / m.sqrt(),
            };
            (st, g)
        })
        .collect()
}

/// The pooled residual profile (stations) of `experiments` = (positions, residuals) per
/// experiment, with noise level `sigma`.
pub fn station_profile(experiments: &[(Vec<f64>, Vec<f64>)], sigma: f64) -> Vec<Station> {
    stations_of(experiments, sigma)
        .into_iter()
        .map(|(s, _)| s)
        .collect()
}

/// The systematic segments of `experiments` = (positions, residuals) per experiment with noise
/// level `sigma` (see the module documentation).
pub fn find_segments(
    experiments: &[(Vec<f64>, Vec<f64>)],
    sigma: f64,
    options: &SegmentOptions,
) -> Vec<Segment> {
    let st = stations_of(experiments, sigma);
    let sign = |j: usize| -> i8 {
        let s = &st[j].0;
        if s.std_error > 0.0 && s.mean.abs() / s.std_error >= options.z_station {
            if s.mean > 0.0 {
                1
            } else {
                -1
            }
        } else {
            0
        }
    };
    let marks: Vec<i8> = (0..st.len()).map(sign).collect();
    let mut candidates: Vec<(usize, usize)> = Vec::new();
    let mut j = 0;
    while j < st.len() {
        if marks[j] == 0 {
            j += 1;
            continue;
        }
        let sg = marks[j];
        let mut end = j;
        let mut i = j + 1;
        while i < st.len() {
            if marks[i] == sg {
                end = i;
                i += 1;
            } else if marks[i] == 0
                && i + 1 < st.len()
                && marks[i + 1] == sg
                && (st[i].0.mean > 0.0) == (sg > 0)
            {
                i += 1;
            } else {
                break;
            }
        }
        candidates.push((j, end));
        j = end + 1;
    }
    let mut pieces = Vec::new();
    for (a, b) in candidates {
        split_levels(&st, a, b, options.z_segment, &mut pieces);
    }
    pieces
        .into_iter()
        .filter_map(|(a, b)| segment_of(&st[a..=b], experiments.len(), sigma, options))
        .collect()
}

/// Weighted mean and its standard error over stations `a..=b`.
fn level(st: &[(Station, Vec<Point>)], a: usize, b: usize) -> (f64, f64) {
    let (mut sum, mut n, mut var) = (0.0, 0.0, 0.0);
    for (s, _) in &st[a..=b] {
        let m = s.count as f64;
        sum += m * s.mean;
        n += m;
        var += (m * s.std_error).powi(2);
    }
    (sum / n, var.sqrt() / n)
}

/// Binary segmentation of a candidate into pieces of different level: splits `a..=b` where
/// the levels of the two parts (each at least 2 stations) differ most, if that difference is
/// at least `z` standard errors, and recurses.
fn split_levels(
    st: &[(Station, Vec<Point>)],
    a: usize,
    b: usize,
    z: f64,
    out: &mut Vec<(usize, usize)>,
) {
    let mut best: Option<(usize, f64)> = None;
    if b >= a + 3 {
        for c in (a + 1)..b {
            if c < a + 2 || c + 1 > b {
                continue;
            }
            let (m1, e1) = level(st, a, c - 1);
            let (m2, e2) = level(st, c, b);
            let zc = (m1 - m2).abs() / (e1 * e1 + e2 * e2).sqrt();
            if zc >= z && best.is_none_or(|(_, zb)| zc > zb) {
                best = Some((c, zc));
            }
        }
    }
    match best {
        Some((c, _)) => {
            split_levels(st, a, c - 1, z, out);
            split_levels(st, c, b, z, out);
        }
        None => out.push((a, b)),
    }
}

fn segment_of(
    st: &[(Station, Vec<Point>)],
    n_experiments: usize,
    sigma: f64,
    options: &SegmentOptions,
) -> Option<Segment> {
    let points: Vec<Point> = st.iter().flat_map(|(_, g)| g.iter().copied()).collect();
    let n = points.len() as f64;
    let mean = points.iter().map(|p| p.r).sum::<f64>() / n;
    let var: f64 = st
        .iter()
        .map(|(s, _)| (s.count as f64 * s.std_error).powi(2))
        .sum::<f64>()
        / (n * n);
    let se = var.sqrt();
    let z = mean / se;
    if !(z.abs() >= options.z_segment && mean.abs() >= options.min_effect) {
        return None;
    }
    let mut per = Vec::new();
    let (mut same, mut signif) = (0, 0);
    for k in 0..n_experiments {
        let r: Vec<f64> = points.iter().filter(|p| p.k == k).map(|p| p.r).collect();
        if r.is_empty() {
            continue;
        }
        let mk = r.iter().sum::<f64>() / r.len() as f64;
        if (mk > 0.0) == (mean > 0.0) && mk != 0.0 {
            same += 1;
            if mk.abs() >= 2.0 * sigma / (r.len() as f64).sqrt() {
                signif += 1;
            }
        }
        per.push((k, mk));
    }
    let spread = if per.len() > 1 {
        let m = per.iter().map(|(_, v)| v).sum::<f64>() / per.len() as f64;
        (per.iter().map(|(_, v)| (v - m).powi(2)).sum::<f64>() / (per.len() - 1) as f64).sqrt()
    } else {
        0.0
    };
    Some(Segment {
        start_m: st[0].0.position_m,
        end_m: st[st.len() - 1].0.position_m,
        stations: st.len(),
        points: points.len(),
        mean,
        std_error: se,
        z,
        spread,
        per_experiment: per,
        same_sign: same,
        significant: signif,
    })
}
