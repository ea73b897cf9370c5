//! Settings with a fixed set of values ([`Named`]): each value's name — what the command line,
//! `params.json`, Python and docs/reference.md write — and a line of help, from which every front end
//! parses and lists them, and (with the `serde` feature) their (de)serialization by that name.
//! The bottom floor of the settings: the methods' and the chain's settings name their values
//! here, and nothing here knows of them.

/// A setting with a fixed set of values, each with the name the command line, `params.json` and
/// docs/reference.md use and a line of help: what a CLI or a binding (Python, a host's UI) parses and
/// lists, so that it mirrors no enum of its own.
pub trait Named: Copy + Send + Sync + 'static {
    /// Every value, the default first.
    const VALUES: &'static [Self];
    /// Its name.
    fn name(self) -> &'static str;
    /// What the value does, in one line.
    fn help(self) -> &'static str;
    /// The value called `name`.
    fn from_name(name: &str) -> Option<Self> {
        Self::VALUES.iter().copied().find(|v| v.name() == name)
    }
}

/// `impl Named` from the inherent `name` and a help line per value, and (with the `serde`
/// feature) (de)serialization by that name.
macro_rules! named {
    ($ty:ty { $($value:ident => $help:literal),+ $(,)? }) => {
        crate::named::serde_by_name!($ty);
        impl Named for $ty {
            const VALUES: &'static [Self] = &[$(<$ty>::$value),+];
            fn name(self) -> &'static str {
                <$ty>::name(self)
            }
            fn help(self) -> &'static str {
                match self {
                    $(<$ty>::$value => $help),+
                }
            }
        }
    };
}
pub(crate) use named;

/// A [`Named`] setting (de)serializes as its name, as the command line and `params.json` write
/// it; an unknown name is an error that lists the known ones.
#[cfg(feature = "serde")]
macro_rules! serde_by_name {
    ($ty:ty) => {
        impl serde::Serialize for $ty {
            fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
                serializer.serialize_str(crate::named::Named::name(*self))
            }
        }

        impl<'de> serde::Deserialize<'de> for $ty {
            fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
                let name = <String as serde::Deserialize>::deserialize(deserializer)?;
                <$ty as crate::named::Named>::from_name(&name)
                    .ok_or_else(|| serde::de::Error::custom(crate::named::unknown::<$ty>(&name)))
            }
        }
    };
}
#[cfg(not(feature = "serde"))]
macro_rules! serde_by_name {
    ($ty:ty) => {};
}
pub(crate) use serde_by_name;

/// `impl FromStr` of a [`Named`] type by its names; an unknown one is an error naming `what` it
/// should have been and listing the names (`unknown method 'gtao' (one of none, lineao, …)`).
macro_rules! from_str_by_name {
    ($ty:ty, $what:literal) => {
        impl std::str::FromStr for $ty {
            type Err = String;

            fn from_str(name: &str) -> Result<$ty, String> {
                <$ty as crate::named::Named>::from_name(name).ok_or_else(|| {
                    let names: Vec<&str> = <$ty as crate::named::Named>::VALUES.iter().map(|v| v.name()).collect();
                    format!("unknown {} '{name}' (one of {})", $what, names.join(", "))
                })
            }
        }
    };
}
pub(crate) use from_str_by_name;

/// What an unknown name of a [`Named`] setting is told: the names it could have been.
#[cfg(feature = "serde")]
pub(crate) fn unknown<T: Named>(name: &str) -> String {
    let names: Vec<&str> = T::VALUES.iter().map(|v| v.name()).collect();
    format!("unknown value '{name}' (one of {})", names.join(", "))
}
