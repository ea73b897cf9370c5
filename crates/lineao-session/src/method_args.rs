//! The methods' own settings as the front ends take them, made from the settings' descriptions
//! ([`lineao::method::setting`]) — not written here: a flag per setting on the command line
//! (`--FLAG VALUE`, under its method's heading, its help with the unit, range and default),
//! the same name as a key of the web page's URL (its query is the viewer's command line), and
//! with `_` as a keyword argument of Python's `render` (serde, [`crate::kwargs`]).
//!
//! Only what was given is kept ([`MethodArgs::given`]). `render` writes it twice
//! ([`MethodArgs::apply`]): before the preset, which depends on some of it (LineAO's variant),
//! and after it with the shorthands ([`MethodArgs::apply_with`]), so that every explicit option
//! wins over the preset.

use clap::builder::TypedValueParser;
use clap::parser::ValueSource;
use clap::{Arg, ArgAction, ArgMatches, Command};
use lineao::method::ChainSetting;
use lineao::method::setting::{Kind, Role, Value};
use lineao::{AoMethod, ChainSettings};

/// The described settings given explicitly, by flag, in the order of the registry.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MethodArgs {
    pub given: Vec<(&'static str, Value)>,
}

/// Every method's described settings, in the registry's order, each once (the first method
/// that lists it: VO area lists VO line's sphere).
pub fn described() -> impl Iterator<Item = (AoMethod, ChainSetting)> {
    let mut seen = std::collections::BTreeSet::new();
    let all = AoMethod::REGISTRY.iter().flat_map(|&m| m.info().settings().map(move |s| (m, s)));
    all.filter(move |(_, s)| seen.insert(s.flag))
}

impl MethodArgs {
    /// Writes every given value into `settings`, after the shorthands' (`--samples` and
    /// `--radius`: [`Role`]) where a setting's own flag is not given: `samples` to the shown
    /// method's (`shown`), `radius` to every method's.
    pub fn apply_with(&self, settings: &mut ChainSettings, shown: AoMethod, samples: Option<u32>, radius: Option<f32>) {
        for (method, setting) in described() {
            let value = match setting.role {
                Some(Role::Samples) if method == shown => samples.map(Value::Count),
                Some(Role::Radius) => radius.map(Value::Number),
                _ => None,
            };
            if let Some(value) = value.filter(|_| !self.given.iter().any(|(flag, _)| *flag == setting.flag)) {
                setting.set(settings, value);
            }
        }
        self.apply(settings);
    }

    /// Gives `flag` the value `value`, as the command line would (replacing what it had).
    pub fn give(&mut self, flag: &'static str, value: Value) {
        self.given.retain(|(f, _)| *f != flag);
        self.given.push((flag, value));
    }

    /// Whether the setting of `flag` was given.
    pub fn gives(&self, flag: &str) -> bool {
        self.given.iter().any(|(f, _)| *f == flag)
    }

    /// Writes every given value into `settings`.
    pub fn apply(&self, settings: &mut ChainSettings) {
        for (flag, value) in &self.given {
            if let Some((_, setting)) = described().find(|(_, s)| s.flag == *flag) {
                setting.set(settings, *value);
            }
        }
    }

    /// The value given for a setting by Python's keyword `keyword` as the command line's text
    /// (`true`/`false` for a switch: given or not), or what is wrong with it (which `kwargs`
    /// says of the keyword).
    fn keyword(&mut self, keyword: &str, text: &str) -> Result<(), String> {
        let Some((_, setting)) = described().find(|(_, s)| s.keyword() == keyword) else {
            return Ok(());
        };
        let value = setting.parse(text)?;
        match (setting.kind, value) {
            (Kind::Switch { given }, Value::Switch(true)) => self.given.push((setting.flag, Value::Switch(given))),
            (Kind::Switch { .. }, _) => {}
            _ => self.given.push((setting.flag, value)),
        }
        Ok(())
    }
}

/// The flag of `setting` (of `method`), its id Python's keyword: its help with the values it
/// takes (`(> 0 world units)`) and its default.
fn arg(method: AoMethod, setting: ChainSetting) -> Arg {
    let mut arg = Arg::new(setting.keyword()).long(setting.flag);
    if let Some(flag) = setting.requires {
        arg = arg.requires(flag.replace('-', "_"));
    }
    if let Kind::Switch { .. } = setting.kind {
        return arg.action(ArgAction::SetTrue).help(setting.help);
    }
    let name = match (setting.kind, setting.unit.name()) {
        (Kind::Choice(names), _) => names.join("|"),
        (_, "") => "N".to_string(),
        (_, unit) => unit.to_uppercase(),
    };
    let help = match setting.kind {
        Kind::Choice(_) => setting.help.to_string(),
        _ => match setting.range().unwrap_or_default() {
            interval if interval.starts_with(['[', '(']) => format!("{} (in {interval})", setting.help),
            range => format!("{} ({range})", setting.help),
        },
    };
    let arg = match setting.kind {
        // clap's own list of the names: the help and the error list them.
        Kind::Choice(names) => arg.value_name(name).value_parser(
            clap::builder::PossibleValuesParser::new(names.iter().copied())
                .map(move |name| Value::Choice(names.iter().copied().find(|n| *n == name).unwrap_or_default())),
        ),
        _ => arg.value_name(name).value_parser(move |text: &str| setting.parse(text)),
    };
    match setting.default {
        // Not one value: said, and nothing given unless the flag is.
        Some(default) => arg.help(format!("{help} [default: {default}]")),
        None => arg.help(help).default_value(setting.default_value(method).to_string()),
    }
}

impl clap::Args for MethodArgs {
    fn augment_args(mut command: Command) -> Command {
        let heading = command.get_next_help_heading().map(str::to_owned);
        for (method, setting) in described() {
            command = command.next_help_heading(method.info().label).arg(arg(method, setting));
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
                        let text: crate::text::Text = map.next_value()?;
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
