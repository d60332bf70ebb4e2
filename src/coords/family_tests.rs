//! Tests of the family table.

use super::*;

#[test]
fn the_outside_policy_names_the_far_field_distance_in_use() {
    let distance = format!(
        "beyond {} cage diagonals",
        crate::coords::mvc::FAR_FIELD_DIAGONALS
    );
    assert!(OUTSIDE_BY_MVC.contains(&distance), "{OUTSIDE_BY_MVC}");
}

#[test]
fn identifiers_are_unique_and_round_trip() {
    for method in Method::ALL {
        assert_eq!(Method::from_id(method.id()), Some(method));
        assert_eq!(
            Method::ALL.iter().filter(|m| m.id() == method.id()).count(),
            1
        );
    }
    assert_eq!(Method::from_id("PMVC"), Some(Method::Pmvc));
    assert_eq!(Method::from_id("nope"), None);
}

#[test]
fn a_parameter_outside_its_range_is_refused_with_its_name_value_and_range() {
    let error = Parameter::Grid.validate(4_294_967_295).unwrap_err();
    assert_eq!(
        error.to_string(),
        "grid 4294967295 is out of range: the harmonic grid must be 4 to 2048"
    );
    let error = Parameter::Resolution.validate(1 << 40).unwrap_err();
    assert!(error.to_string().contains("1099511627776"), "{error}");
    // 0 is exact PMVC's code: stored options hold it, a user names it.
    assert_eq!(Parameter::Resolution.validate(0), Ok(EXACT_RESOLUTION));
    let spec = Parameter::Resolution.spec();
    assert!(spec.validate_number(0).is_err());
    assert_eq!(spec.parse(" Exact "), Ok(EXACT_RESOLUTION));
    assert_eq!(spec.parse("64"), Ok(64));
    let refused = spec.parse("0").unwrap_err();
    assert!(
        refused.ends_with("must be 1 to 1024, or \"exact\""),
        "{refused}"
    );
    assert!(Parameter::Grid.spec().parse("exact").is_err());
    assert!(Parameter::Grid.validate(3).is_err());
    assert_eq!(Parameter::Resolution.validate(1024), Ok(1024));
    assert_eq!(Parameter::Grid.validate(4), Ok(4));
}

#[test]
fn every_family_parameter_is_its_parameters_spec_and_offers_valid_choices() {
    for method in Method::ALL {
        let Some(spec) = method.spec().parameter else {
            continue;
        };
        // A family may offer its own label, choices and default for a
        // parameter it shares (BBW's grid), not its own range or flag.
        let shared = spec.key.spec();
        assert_eq!(
            (spec.flag, spec.min, spec.max),
            (shared.flag, shared.min, shared.max)
        );
        for &value in spec.choices.iter().chain([&spec.default]) {
            assert_eq!(spec.validate(value.into()), Ok(value), "{}", spec.label);
        }
    }
}

#[test]
fn next_visits_every_family_once_per_cycle() {
    let mut seen = vec![Method::ALL[0]];
    for _ in 1..Method::ALL.len() {
        seen.push(seen.last().unwrap().next());
    }
    seen.sort();
    assert_eq!(seen, Method::ALL.to_vec());
    assert_eq!(Method::ALL.last().unwrap().next(), Method::ALL[0]);
}
