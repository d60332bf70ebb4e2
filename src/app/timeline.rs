//! The timeline: named poses placed at times (seconds), played with linear
//! blends between neighbouring keys, and exported as a glTF animation. Pure
//! functions of the named poses; the Timeline panel plays them.

use super::document::NamedPose;
use glam::DVec3;

/// The longest time a key may be placed at: an hour, past any shot this editor
/// poses, and small enough that f32 seconds in glTF keep millisecond steps.
pub const LONGEST_SECONDS: f64 = 3600.0;

/// The one check of a key's time, wherever it comes from (panel, session).
pub fn check_key_time(seconds: f64) -> Result<f64, String> {
    if !seconds.is_finite() || !(0.0..=LONGEST_SECONDS).contains(&seconds) {
        return Err(format!(
            "a key's time must be between 0 and {LONGEST_SECONDS} s, not {seconds}"
        ));
    }
    Ok(seconds)
}

/// The keys: (time, index of the named pose), by time.
pub fn keys(named: &[NamedPose]) -> Vec<(f64, usize)> {
    let mut keys: Vec<(f64, usize)> = named
        .iter()
        .enumerate()
        .filter_map(|(index, pose)| pose.time.map(|t| (t, index)))
        .collect();
    keys.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    keys
}

/// The first and last key's times, when there are keys.
pub fn span(named: &[NamedPose]) -> Option<(f64, f64)> {
    let keys = keys(named);
    Some((keys.first()?.0, keys.last()?.0))
}

/// The pose at `seconds`: the first key's before it, the last key's after it,
/// and between two keys the linear blend of their poses.
pub fn pose_at(named: &[NamedPose], seconds: f64) -> Option<Vec<DVec3>> {
    let keys = keys(named);
    let &(first_time, first) = keys.first()?;
    if seconds <= first_time {
        return Some(named[first].positions.clone());
    }
    for pair in keys.windows(2) {
        let ((t0, a), (t1, b)) = (pair[0], pair[1]);
        if seconds < t1 {
            let amount = (seconds - t0) / (t1 - t0);
            let (from, to) = (&named[a].positions, &named[b].positions);
            return Some(
                from.iter()
                    .zip(to)
                    .map(|(&p, &q)| p + (q - p) * amount)
                    .collect(),
            );
        }
    }
    let &(_, last) = keys.last()?;
    Some(named[last].positions.clone())
}

/// Where playback started at `start_seconds` is after `elapsed` seconds,
/// looping over the keys' span.
pub fn looped(span: (f64, f64), start_seconds: f64, elapsed: f64) -> f64 {
    let (first, last) = span;
    let length = last - first;
    if length <= 0.0 {
        return first;
    }
    first + (start_seconds - first + elapsed).rem_euclid(length)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pose(name: &str, x: f64, time: Option<f64>) -> NamedPose {
        NamedPose {
            name: name.into(),
            positions: vec![DVec3::new(x, 0.0, 0.0), DVec3::new(0.0, x, 0.0)],
            time,
        }
    }

    #[test]
    fn poses_between_keys_are_linear_blends_and_outside_them_the_nearest_key() {
        // Out of order in the list, one not on the timeline.
        let named = [
            pose("late", 4.0, Some(2.0)),
            pose("off", 100.0, None),
            pose("early", 0.0, Some(0.0)),
            pose("middle", 1.0, Some(1.0)),
        ];
        assert_eq!(keys(&named), [(0.0, 2), (1.0, 3), (2.0, 0)]);
        assert_eq!(span(&named), Some((0.0, 2.0)));
        let x_at = |t| pose_at(&named, t).unwrap()[0].x;
        assert_eq!(x_at(-1.0), 0.0);
        assert_eq!(x_at(0.5), 0.5);
        assert_eq!(x_at(1.0), 1.0, "exactly the key's pose at its time");
        assert_eq!(x_at(1.25), 1.75);
        assert_eq!(x_at(2.0), 4.0);
        assert_eq!(x_at(9.0), 4.0);
    }

    #[test]
    fn no_keys_no_pose() {
        assert_eq!(pose_at(&[pose("off", 1.0, None)], 0.0), None);
        assert_eq!(span(&[]), None);
    }

    #[test]
    fn playback_loops_over_the_span() {
        assert_eq!(looped((1.0, 3.0), 1.0, 0.5), 1.5);
        assert_eq!(looped((1.0, 3.0), 2.5, 1.0), 1.5);
        assert_eq!(looped((1.0, 1.0), 1.0, 5.0), 1.0);
    }

    #[test]
    fn key_times_are_checked_in_one_place() {
        assert_eq!(check_key_time(1.5), Ok(1.5));
        for bad in [-0.1, f64::NAN, f64::INFINITY, LONGEST_SECONDS + 1.0] {
            assert!(check_key_time(bad).is_err(), "{bad}");
        }
    }
}
