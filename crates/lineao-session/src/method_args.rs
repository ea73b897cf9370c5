//! The methods' own settings as the front ends take them, made from the settings' descriptions
//! ([`lineao::method::setting`]) — not written here: a flag per setting on the command line
//! (`--FLAG VALUE`, under its method's heading, its help with the unit, range and default),
//! the same name as a key of the web page's URL (its query is the viewer's command line), and
//! with `_` as a keyword argument of Python's `render` (serde, [`crate::kwargs`]).
//!
//! Only what was given is kept ([`MethodArgs::given`]), and [`MethodArgs::apply`] writes it
//! over the preset's values, as every explicit option wins over the preset.

use clap::parser::ValueSource;
use clap::{Arg, ArgAction, ArgMatches, Command};
use lineao::method::setting::{Kind, Setting, Value};
use lineao::{AoMethod, ChainSettings};

/// The described settings given explicitly, by flag, in the order of the registry.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MethodArgs {
    pub given: Vec<(&'static str, Value)>,
}

/// Every method's described settings, in the registry's order.
pub fn described() -> impl Iterator<Item = (AoMethod, &'static Setting)> {
    AoMethod::REGISTRY.iter().flat_map(|&m| m.info().settings.iter().map(move |s| (m, s)))
}

impl MethodArgs {
    /// Writes every given value into `settings`.
    pub fn apply(&self, settings: &mut ChainSettings) {
        for (flag, value) in &self.given {
            if let Some((_, setting)) = described().find(|(_, s)| s.flag == *flag) {
                (setting.set)(settings, *value);
            }
        }
    }

    /// The value given for a setting by Python's keyword `keyword` as the command line's text
    /// (`true`/`false` for a switch: given or not), or an error that names the keyword.
    fn keyword(&mut self, keyword: &str, text: &str) -> Result<(), String> {
        let Some((_, setting)) = described().find(|(_, s)| s.keyword() == keyword) else {
            return Ok(());
        };
        let value = setting.parse(text).map_err(|e| format!("{keyword}: {e}"))?;
        match (setting.kind, value) {
            (Kind::Switch { given }, Value::Switch(true)) => self.given.push((setting.flag, Value::Switch(given))),
            (Kind::Switch { .. }, _) => {}
            _ => self.given.push((setting.flag, value)),
        }
        Ok(())
    }
}

/// The flag of `setting` (of `method`), its id Python's keyword.
fn arg(method: AoMethod, setting: &'static Setting) -> Arg {
    let default = setting.default_value(method);
    let arg = Arg::new(setting.keyword()).long(setting.flag);
    match setting.kind {
        Kind::Switch { .. } => arg.action(ArgAction::SetTrue).help(setting.help),
        Kind::Number { .. } | Kind::Count { .. } => {
            let range = setting.range().unwrap_or_default();
            let name = if setting.unit.is_empty() { "N".to_string() } else { setting.unit.to_uppercase() };
            arg.value_name(name)
                .help(format!("{} ({range})", setting.help))
                .default_value(default.to_string())
                .value_parser(move |text: &str| setting.parse(text))
        }
    }
}

impl clap::Args for MethodArgs {
    fn augment_args(mut command: Command) -> Command {
        let heading = command.get_next_help_heading().map(str::to_owned);
        for &method in AoMethod::REGISTRY {
            let info = method.info();
            if info.settings.is_empty() {
                continue;
            }
            command = command.next_help_heading(info.label);
            for setting in info.settings {
                command = command.arg(arg(method, setting));
            }
        }
        match heading {
            Some(heading) => command.next_help_heading(heading),
            None => command.next_help_heading(None::<&str>),
        }
    }

    fn augment_args_for_update(command: Command) -> Command {
        MethodArgs::augment_args(command)
    }
}

impl clap::FromArgMatches for MethodArgs {
    fn from_arg_matches(matches: &ArgMatches) -> Result<MethodArgs, clap::Error> {
        let given = described().filter_map(|(_, setting)| {
            let id = setting.keyword();
            match setting.kind {
                Kind::Switch { given } => matches.get_flag(&id).then_some((setting.flag, Value::Switch(given))),
                _ if matches.value_source(&id) == Some(ValueSource::CommandLine) => {
                    matches.get_one::<Value>(&id).map(|value| (setting.flag, *value))
                }
                _ => None,
            }
        });
        Ok(MethodArgs { given: given.collect() })
    }

    fn update_from_arg_matches(&mut self, matches: &ArgMatches) -> Result<(), clap::Error> {
        *self = MethodArgs::from_arg_matches(matches)?;
        Ok(())
    }
}

/// Python's keyword arguments (flattened into `render`'s): each described setting's keyword,
/// its value as the command line's text, parsed as the flag parses it.
impl<'de> serde::Deserialize<'de> for MethodArgs {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<MethodArgs, D::Error> {
        struct Visitor;
        impl<'de> serde::de::Visitor<'de> for Visitor {
            type Value = MethodArgs;

            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("the methods' settings by keyword")
            }

            fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<MethodArgs, A::Error> {
                let mut args = MethodArgs::default();
                while let Some(key) = map.next_key::<String>()? {
                    if described().any(|(_, s)| s.keyword() == key) {
                        let text: crate::kwargs::Text = map.next_value()?;
                        args.keyword(&key, &text.0).map_err(serde::de::Error::custom)?;
                    } else {
                        map.next_value::<serde::de::IgnoredAny>()?;
                    }
                }
                Ok(args)
            }
        }
        d.deserialize_map(Visitor)
    }
}
