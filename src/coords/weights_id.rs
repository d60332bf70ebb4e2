//! Which weights a viewer holds: a family's, or a twin of it bound another
//! way to show what that changes.

use super::family::{Method, QuadSupport};

/// One set of weights a viewer holds: a family as bound with the viewer's
/// settings, or a twin of it, the same family bound another way to show what
/// that changes (quads split along a diagonal, or the parameter at its
/// reference value: PMVC exact against its cube map).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct WeightsId {
    pub method: Method,
    pub twin: Option<Twin>,
}

/// How a twin differs from its family as the viewer binds it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Twin {
    /// The cage's quads split along this diagonal.
    Split(crate::geometry::QuadSplit),
    /// The family's parameter at its first named value (PMVC's "exact"),
    /// which the family's other values approximate.
    Reference,
}

impl Twin {
    /// The options of this twin of a family the viewer binds with `setting`;
    /// `None` where the twin would be the family itself or could not differ
    /// (a family that takes only triangles has no split twin, one without a
    /// named value no reference).
    pub fn options(
        self,
        setting: crate::coords::BindOptions,
    ) -> Option<crate::coords::BindOptions> {
        match self {
            Twin::Split(split) => {
                let takes_patches =
                    matches!(setting.method.spec().quads, QuadSupport::Patches { .. });
                (takes_patches && split != setting.quads).then_some(crate::coords::BindOptions {
                    quads: split,
                    ..setting
                })
            }
            Twin::Reference => {
                let (spec, value) = setting.parameter()?;
                let reference = spec.named.first()?.value;
                (value != reference).then(|| {
                    let mut options = setting;
                    options.set(spec.key, reference);
                    options
                })
            }
        }
    }

    /// Whether weights bound with `options` are this twin.
    pub fn matches(self, options: &crate::coords::BindOptions) -> bool {
        match self {
            Twin::Split(split) => options.quads == split,
            Twin::Reference => options
                .parameter()
                .is_some_and(|(spec, value)| spec.named.first().is_some_and(|n| n.value == value)),
        }
    }
}

impl WeightsId {
    /// `method` as the viewer binds it.
    pub const fn of(method: Method) -> Self {
        Self { method, twin: None }
    }

    /// `method`'s twin `twin`.
    pub fn twin(method: Method, twin: Twin) -> Self {
        Self {
            method,
            twin: Some(twin),
        }
    }

    /// `method` with the quads split along `split`.
    pub fn split(method: Method, split: crate::geometry::QuadSplit) -> Self {
        Self::twin(method, Twin::Split(split))
    }

    /// Which weights a bind with `options` gives, where the viewer binds the
    /// family with `setting`: the family's own, or one of its twins.
    pub fn of_bind(
        options: &crate::coords::BindOptions,
        setting: &crate::coords::BindOptions,
    ) -> Self {
        let method = options.method;
        if options.quads != setting.quads {
            Self::split(method, options.quads)
        } else if !options.same_weights_as(setting) && Twin::Reference.matches(options) {
            Self::twin(method, Twin::Reference)
        } else {
            Self::of(method)
        }
    }
}

impl From<Method> for WeightsId {
    fn from(method: Method) -> Self {
        Self::of(method)
    }
}

impl std::fmt::Display for WeightsId {
    /// "PMVC", "PMVC (shorter split)" or "PMVC (exact)".
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let name = self.method.name();
        match self.twin {
            None => write!(f, "{name}"),
            Some(Twin::Split(split)) => write!(f, "{name} ({} split)", split.id()),
            Some(Twin::Reference) => {
                let reference = (self.method.spec().parameter)
                    .and_then(|spec| spec.named.first())
                    .map_or("reference", |named| named.name);
                write!(f, "{name} ({reference})")
            }
        }
    }
}
