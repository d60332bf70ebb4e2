//! Colour maps of the coordinate heatmaps, on the CPU. The WGSL functions of the
//! same names in `shaders/render_mesh.wgsl` are their GPU twins; the colour bar is
//! drawn with these, and a test reads the shader's colours back against them.
//!
//! Weights are shown with a diverging map centred at zero, as in the paper's
//! Figure 2: blue for negative, white at 0, red for positive. A value is first
//! scaled to t ∈ [−1, 1] against a magnitude `limit` shared by the views compared.

/// Colour at t = −1.
pub const NEGATIVE: [f32; 3] = [0.16, 0.29, 0.80];
/// Colour at t = 0.
pub const ZERO: [f32; 3] = [0.97, 0.97, 0.97];
/// Colour at t = +1.
pub const POSITIVE: [f32; 3] = [0.80, 0.08, 0.10];
/// The negativity view's colour for a vertex outside the cage: its weights are
/// MVC's by the outside policy, not the shown family's, so they are not painted
/// as that family's negativity.
pub const OUTSIDE: [f32; 3] = [0.55, 0.55, 0.55];
/// Decades of magnitude shown by the log scale: |v| from `limit`·10⁻³ to `limit`.
pub const LOG_DECADES: f32 = 3.0;

/// How a value's magnitude maps to the colour's strength.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Scale {
    #[default]
    Linear,
    /// Sign kept, magnitude on a log axis over [`LOG_DECADES`] decades below the limit.
    LogMagnitude,
}

/// `value` scaled to t ∈ [−1, 1] against `limit` (> 0).
pub fn scaled(value: f32, limit: f32, scale: Scale) -> f32 {
    let limit = limit.max(f32::MIN_POSITIVE);
    match scale {
        Scale::Linear => (value / limit).clamp(-1.0, 1.0),
        Scale::LogMagnitude => {
            let magnitude = value.abs() / limit;
            if magnitude <= 0.0 {
                return 0.0;
            }
            let strength = (1.0 + magnitude.log10() / LOG_DECADES).clamp(0.0, 1.0);
            strength.copysign(value)
        }
    }
}

/// The diverging map: blue at −1, white at 0, red at +1, linear in between.
pub fn diverging(t: f32) -> [f32; 3] {
    let t = t.clamp(-1.0, 1.0);
    let (end, amount) = if t < 0.0 {
        (NEGATIVE, -t)
    } else {
        (POSITIVE, t)
    };
    std::array::from_fn(|k| ZERO[k] + (end[k] - ZERO[k]) * amount)
}

/// The colour of `value` in a heatmap whose scale reaches `limit`.
pub fn heat_colour(value: f32, limit: f32, scale: Scale) -> [f32; 3] {
    diverging(scaled(value, limit, scale))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: [f32; 3], b: [f32; 3]) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-6)
    }

    #[test]
    fn zero_is_white_and_the_ends_are_blue_and_red() {
        assert!(close(heat_colour(0.0, 0.5, Scale::Linear), ZERO));
        assert!(close(heat_colour(-0.5, 0.5, Scale::Linear), NEGATIVE));
        assert!(close(heat_colour(0.5, 0.5, Scale::Linear), POSITIVE));
        // Beyond the limit the colour saturates.
        assert!(close(heat_colour(-3.0, 0.5, Scale::Linear), NEGATIVE));
    }

    #[test]
    fn halfway_is_halfway_between_white_and_the_end() {
        let half_red = heat_colour(0.25, 0.5, Scale::Linear);
        for k in 0..3 {
            assert!((half_red[k] - (ZERO[k] + POSITIVE[k]) / 2.0).abs() < 1e-6);
        }
        let quarter_blue = heat_colour(-0.1, 0.4, Scale::Linear);
        assert!(
            quarter_blue[2] > quarter_blue[0],
            "negative values are bluish"
        );
    }

    #[test]
    fn log_scale_spreads_small_magnitudes_and_keeps_the_sign() {
        assert_eq!(scaled(1.0, 1.0, Scale::LogMagnitude), 1.0);
        assert!((scaled(0.1, 1.0, Scale::LogMagnitude) - 2.0 / 3.0).abs() < 1e-6);
        assert!((scaled(-0.01, 1.0, Scale::LogMagnitude) + 1.0 / 3.0).abs() < 1e-6);
        assert_eq!(scaled(1e-6, 1.0, Scale::LogMagnitude), 0.0);
        assert_eq!(scaled(0.0, 1.0, Scale::LogMagnitude), 0.0);
        // The linear scale shows 0.01 as almost white, the log scale clearly.
        assert!(scaled(0.01, 1.0, Scale::Linear) < scaled(0.01, 1.0, Scale::LogMagnitude));
    }
}
