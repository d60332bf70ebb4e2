//! Parameters in saved files (sessions, weights metadata): numbers, except a
//! named value, which is written as its name (`"resolution": "exact"`) so that
//! the file says what it means; either form is read back. Used through
//! `#[serde(with = "crate::coords::parameter_values")]` on a map from a
//! parameter's id to its value.

use super::family::Parameter;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::collections::BTreeMap;

#[derive(Serialize, Deserialize)]
#[serde(untagged)]
enum Written {
    Number(u64),
    Name(String),
    /// A parameter in `1/scale` units, as the decimal it stands for.
    Decimal(f64),
}

fn parameter_of(id: &str) -> Option<Parameter> {
    Parameter::ALL.into_iter().find(|p| p.id() == id)
}

pub fn serialize<T, S>(values: &BTreeMap<String, T>, serializer: S) -> Result<S::Ok, S::Error>
where
    T: Copy + Into<u64>,
    S: Serializer,
{
    let written: BTreeMap<&str, Written> = values
        .iter()
        .map(|(id, &value)| {
            let value: u64 = value.into();
            let name = parameter_of(id).and_then(|parameter| {
                u32::try_from(value)
                    .ok()
                    .and_then(|value| parameter.spec().name_of(value))
            });
            let decimal = parameter_of(id)
                .map(|parameter| parameter.spec())
                .filter(|spec| spec.scale > 1);
            let written = match (name, decimal) {
                (Some(name), _) => Written::Name(name.to_owned()),
                (None, Some(spec)) => {
                    Written::Decimal((value as f64 - f64::from(spec.zero)) / f64::from(spec.scale))
                }
                (None, None) => Written::Number(value),
            };
            (id.as_str(), written)
        })
        .collect();
    written.serialize(serializer)
}

/// A name is read by its parameter's spec; numbers are left to the file's own
/// check of each value, which names the file.
pub fn deserialize<'de, T, D>(deserializer: D) -> Result<BTreeMap<String, T>, D::Error>
where
    T: TryFrom<u64>,
    D: Deserializer<'de>,
{
    let written = BTreeMap::<String, Written>::deserialize(deserializer)?;
    written
        .into_iter()
        .map(|(id, value)| {
            let number = match value {
                Written::Decimal(decimal) => {
                    let spec = parameter_of(&id)
                        .filter(|parameter| parameter.spec().scale > 1)
                        .ok_or_else(|| {
                            serde::de::Error::custom(format!(
                                "\"{id}\": {decimal} is not a whole number"
                            ))
                        })?
                        .spec();
                    u64::from(
                        spec.validate_decimal(decimal)
                            .map_err(serde::de::Error::custom)?,
                    )
                }
                Written::Number(number) => match parameter_of(&id) {
                    // A decimal parameter's whole number (ν 0 written as 0).
                    Some(parameter) if parameter.spec().scale > 1 => u64::from(
                        (parameter.spec())
                            .validate_decimal(number as f64)
                            .map_err(serde::de::Error::custom)?,
                    ),
                    Some(parameter) => {
                        let spec = parameter.spec();
                        let named = u32::try_from(number)
                            .ok()
                            .and_then(|value| spec.name_of(value))
                            .is_some();
                        if named {
                            if let Err(error) = spec.validate_number(number) {
                                return Err(serde::de::Error::custom(error.to_string()));
                            }
                        }
                        number
                    }
                    None => number,
                },
                Written::Name(name) => {
                    let parameter = parameter_of(&id).ok_or_else(|| {
                        serde::de::Error::custom(format!("\"{id}\" is not a parameter"))
                    })?;
                    let spec = parameter.spec();
                    let named = spec.named.iter().find(|n| n.name == name).ok_or_else(|| {
                        let names: Vec<String> = spec
                            .named
                            .iter()
                            .map(|n| format!("\"{}\"", n.name))
                            .collect();
                        serde::de::Error::custom(format!(
                            "\"{id}\": {name:?} is not a number{}",
                            if names.is_empty() {
                                String::new()
                            } else {
                                format!(" or {}", names.join(", "))
                            }
                        ))
                    })?;
                    u64::from(named.value)
                }
            };
            let value = T::try_from(number).map_err(|_| {
                serde::de::Error::custom(format!("\"{id}\": {number} is out of range"))
            })?;
            Ok((id, value))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Serialize, Deserialize, Debug, PartialEq)]
    struct File {
        #[serde(with = "super")]
        parameters: BTreeMap<String, u32>,
    }

    #[test]
    fn exact_is_written_by_name_and_read_back_either_way() {
        let file = File {
            parameters: [("resolution".to_owned(), 0), ("grid".to_owned(), 64)].into(),
        };
        let text = serde_json::to_string(&file).unwrap();
        assert_eq!(text, r#"{"parameters":{"grid":64,"resolution":"exact"}}"#);
        assert_eq!(serde_json::from_str::<File>(&text).unwrap(), file);
        let numbers: File =
            serde_json::from_str(r#"{"parameters":{"resolution":32,"grid":64}}"#).unwrap();
        assert_eq!(numbers.parameters["resolution"], 32);
        // A grid has no names: a string is not one of its values.
        assert!(serde_json::from_str::<File>(r#"{"parameters":{"grid":"64"}}"#).is_err());
    }

    #[test]
    fn exact_s_code_as_a_number_is_refused() {
        let error = serde_json::from_str::<File>(r#"{"parameters":{"resolution":0}}"#)
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("resolution 0") && error.contains("\"exact\""),
            "{error}"
        );
    }

    #[test]
    fn unknown_names_are_refused() {
        let error = serde_json::from_str::<File>(r#"{"parameters":{"resolution":"fine"}}"#)
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("resolution") && error.contains("exact"),
            "{error}"
        );
        let error = serde_json::from_str::<File>(r#"{"parameters":{"colour":"exact"}}"#)
            .unwrap_err()
            .to_string();
        assert!(error.contains("colour"), "{error}");
    }
}
