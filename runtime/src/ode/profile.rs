//! Time profiles of a scene's drives and loads: the quintic time scaling of a computed-torque
//! drive and a tabulated wrench.

/// Quintic time scaling `s(τ) = 10τ³ − 15τ⁴ + 6τ⁵`, `τ = t / duration` clamped to `[0, 1]`,
/// of a computed-torque drive at `t`: `(s, ṡ, s̈)` in time (`ṡ = s̈ = 0` from `duration` on).
#[must_use]
pub fn quintic(t: f64, duration: f64) -> (f64, f64, f64) {
    let tau = (t / duration).clamp(0.0, 1.0);
    let s = tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau);
    if t >= duration {
        return (s, 0.0, 0.0);
    }
    let ds = 30.0 * tau * tau * (1.0 - tau) * (1.0 - tau);
    let dds = 60.0 * tau * (1.0 - tau) * (1.0 - 2.0 * tau);
    (s, ds / duration, dds / (duration * duration))
}

/// A tabulated force and moment at `t`: linear between samples, held at the first (last)
/// sample before (after) the table. `time` is strictly increasing, `force` and `moment` have
/// its length; an empty table (or a short `force`/`moment`) gives zeros.
#[must_use]
pub fn table(
    t: f64,
    time: &[f64],
    force: &[[f64; 3]],
    moment: &[[f64; 3]],
) -> ([f64; 3], [f64; 3]) {
    // First sample strictly after t.
    let k = time.partition_point(|&tk| tk <= t);
    let at = |v: &[[f64; 3]], i: usize| v.get(i).copied().unwrap_or([0.0; 3]);
    if k == 0 {
        return (at(force, 0), at(moment, 0));
    }
    if k == time.len() {
        return (at(force, k - 1), at(moment, k - 1));
    }
    let s = (t - time[k - 1]) / (time[k] - time[k - 1]);
    let lerp = |v: &[[f64; 3]]| {
        let (a, b) = (at(v, k - 1), at(v, k));
        [0, 1, 2].map(|i| a[i] + s * (b[i] - a[i]))
    };
    (lerp(force), lerp(moment))
}
