//! A method's settings as they describe themselves: for each, the flag it is given by, its
//! help, unit, range and default ([`About`]), and how it is read from and written to the
//! method's own settings ([`Setting`]).
//!
//! A method lists its settings in its registry entry (its `Own`); from that one table the
//! front ends make what a user sees — the command line's flags (`lineao render --help` shows
//! each with its unit and default), Python's keyword arguments (the flag with `_`), the
//! viewer's sliders and checkboxes, the web page's URL keys (the flag) — and the chain checks
//! each value against its range, naming the flag. The `--settings` JSON is the settings type's
//! own serde: the method's field of the chain's settings, which its registry line declares.

/// What a setting is, for a user: its flag, help, unit, range and default.
/// [`About::BASE`] fills what most leave as it is: `About { flag: "…", …, ..About::BASE }`.
#[derive(Clone, Copy, Debug)]
pub struct About {
    /// The command line's flag without its dashes (`ssao-samples`): the web page's URL key too;
    /// Python's keyword is it with `_` ([`About::keyword`]).
    pub flag: &'static str,
    /// Its name in a method's panel of controls (`samples`).
    pub label: &'static str,
    /// One line of help: what it changes (the unit, range and default are added from the
    /// fields below).
    pub help: &'static str,
    /// What it is counted in.
    pub unit: Unit,
    /// Its values.
    pub kind: Kind,
    /// What the help says of its default where that is not one value (`"the preset's; paper
    /// 2"`, `"the radius"`); `None`: its value in the default settings.
    pub default: Option<&'static str>,
    /// The command line's shorthand that gives it too where its method is shown.
    pub role: Option<Role>,
    /// The flag it means nothing without (VO's `combine` needs `radius2`): the command line
    /// refuses it alone.
    pub requires: Option<&'static str>,
}

/// One setting of a method whose own settings are `S`: what it is, and how it is read and
/// written. [`Setting::BASE`] fills what most leave as it is.
pub struct Setting<S> {
    /// What it is, for a user.
    pub about: About,
    /// Whether it means anything under these settings (LineAO's base radius only in its
    /// `reference` variant): a panel shows it only then.
    pub applies: fn(&S) -> bool,
    /// Its value in `settings`, where the chain around them is `context`.
    pub get: fn(&S, &Context) -> Value,
    /// Puts `value` (of its [`About::kind`]) into `settings`.
    pub set: fn(&mut S, Value),
}

impl<S> Setting<S> {
    /// What most settings leave as it is: always applying. (`about`, `get` and `set` are each
    /// setting's own.)
    pub const BASE: Setting<S> =
        Setting { about: About::BASE, applies: |_| true, get: |_, _| Value::Switch(false), set: |_, _| {} };
}

/// What a method's settings need of the chain around them: the line width (LineAO's r0 follows
/// it), whether the lines are drawn as tubes (r0 then grows with depth instead), and the zoom
/// unit (a preset's reach is in zoom units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Context {
    /// The lines' width in pixels.
    pub line_width_px: f32,
    /// Whether the lines are drawn as tubes.
    pub tubes: bool,
    /// World units per zoom unit.
    pub zoom_unit: f32,
}

/// What a [`Setting`] is counted in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unit {
    /// No unit (a count, a share, a choice).
    None,
    /// Pixels.
    Px,
    /// Zoom units (z(P)'s: 1 mm for tractograms).
    ZoomUnits,
    /// The data's units (mm for tractograms): a panel's slider spans its range times the zoom
    /// unit.
    WorldUnits,
}

impl Unit {
    /// Its name in help and errors (`""` for none).
    pub fn name(self) -> &'static str {
        match self {
            Unit::None => "",
            Unit::Px => "px",
            Unit::ZoomUnits => "zoom units",
            Unit::WorldUnits => "world units",
        }
    }
}

/// What values a [`Setting`] takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kind {
    /// A number in `[min, max]`, or `(min, max]` where `open`; `log`: a slider moves it by
    /// factors.
    Number {
        /// The least value.
        min: f32,
        /// The greatest value.
        max: f32,
        /// Whether `min` itself is left out.
        open: bool,
        /// Whether a slider moves it by factors.
        log: bool,
    },
    /// Any finite number above `min` (`> min` where `open`, else `≥ min`); a panel's slider
    /// spans `slider` (by factors where `log`).
    Above {
        /// The bound below.
        min: f32,
        /// Whether `min` itself is left out.
        open: bool,
        /// What a panel's slider spans.
        slider: [f32; 2],
        /// Whether a slider moves it by factors.
        log: bool,
    },
    /// A whole number in `min..=max`.
    Count {
        /// The least value.
        min: u32,
        /// The greatest value.
        max: u32,
    },
    /// One of these whole numbers (VO's sample sets).
    Counts(&'static [u32]),
    /// One of these names ([`crate::Named`] values').
    Choice(&'static [&'static str]),
    /// On or off. The flag sets it to `given` (`--no-normal-clamp` gives `false`), so its
    /// default is the other.
    Switch {
        /// What the flag sets it to.
        given: bool,
    },
    /// A length > 0 ([`Value::Number`], in its unit), or a share in (0 %, 100 %] of the longest
    /// side of the scene's axis-aligned bounds written with `%` ([`Value::Share`]: the ray
    /// tracer's reach, LineVis's 20 %); a panel's slider spans `slider` by factors.
    Reach {
        /// What a panel's slider spans.
        slider: [f32; 2],
    },
}

/// The shorthands of the command line that give a setting of the method shown.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// `--samples`.
    Samples,
    /// `--radius`.
    Radius,
}

/// A setting's value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    /// A number, in the setting's unit.
    Number(f32),
    /// A whole number.
    Count(u32),
    /// One of the setting's names.
    Choice(&'static str),
    /// On or off.
    Switch(bool),
    /// A share of the scene's longest side ([`Kind::Reach`]), as a fraction (`20%`: 0.2).
    Share(f32),
}

impl std::fmt::Display for Value {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Value::Number(x) => write!(f, "{x}"),
            Value::Count(n) => write!(f, "{n}"),
            Value::Choice(name) => f.write_str(name),
            Value::Switch(on) => f.write_str(if *on { "on" } else { "off" }),
            Value::Share(share) => write!(f, "{}%", share * 100.0),
        }
    }
}

impl Value {
    /// The number (a share's fraction); a switch is 0 or 1, a choice NaN.
    pub fn as_f32(self) -> f32 {
        match self {
            Value::Number(x) | Value::Share(x) => x,
            Value::Count(n) => n as f32,
            Value::Choice(_) => f32::NAN,
            Value::Switch(on) => f32::from(u8::from(on)),
        }
    }

    /// The `T` it names (a choice; anything else: `T`'s default).
    pub fn named<T: crate::Named + Default>(self) -> T {
        match self {
            Value::Choice(name) => T::VALUES.iter().copied().find(|v| v.name() == name).unwrap_or_default(),
            _ => T::default(),
        }
    }

    /// The whole number (a number rounded down, a switch 0 or 1).
    pub fn as_u32(self) -> u32 {
        match self {
            Value::Count(n) => n,
            other => other.as_f32() as u32,
        }
    }

    /// Whether it is on (a number: not 0).
    pub fn is_on(self) -> bool {
        match self {
            Value::Switch(on) => on,
            other => other.as_f32() != 0.0,
        }
    }
}

impl About {
    /// What most settings leave as it is: no unit, their default value, no shorthand. (`flag`,
    /// `label`, `help` and `kind` are each setting's own.)
    pub const BASE: About = About {
        flag: "",
        label: "",
        help: "",
        unit: Unit::None,
        kind: Kind::Switch { given: true },
        default: None,
        role: None,
        requires: None,
    };

    /// A sphere's radius in world units that `--radius` gives and the preset sets (paper 2):
    /// SSAO's and VO's.
    pub const SPHERE_RADIUS: About = About {
        label: "radius",
        unit: Unit::WorldUnits,
        kind: Kind::Above { min: 0.0, open: true, slider: [0.1, 20.0], log: true },
        default: Some("the preset's; paper 2"),
        role: Some(Role::Radius),
        ..About::BASE
    };

    /// Python's keyword argument: the flag with `_` (`ssao_samples`).
    pub fn keyword(&self) -> String {
        self.flag.replace('-', "_")
    }

    /// Its range in words (`[0.25, 4] zoom units`, `(0, 1]`, `1..=256`, `> 0 world units`, `≥ 0 px`, `5, 7 or 9`, `crytek or
    /// sphere`), or `None` for a switch.
    pub fn range(&self) -> Option<String> {
        let unit = match self.unit.name() {
            "" => String::new(),
            name => format!(" {name}"),
        };
        let listed = |items: Vec<String>| match items.split_last() {
            Some((last, [])) => last.clone(),
            Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
            None => String::new(),
        };
        match self.kind {
            Kind::Number { min, max, open, .. } => Some(format!("{}{min}, {max}]{unit}", if open { "(" } else { "[" })),
            Kind::Above { min, open, .. } => Some(format!("{} {min}{unit}", if open { ">" } else { "≥" })),
            Kind::Count { min, max } => Some(format!("{min}..={max}{unit}")),
            Kind::Counts(counts) => Some(listed(counts.iter().map(u32::to_string).collect()) + &unit),
            Kind::Choice(names) => Some(listed(names.iter().map(|n| n.to_string()).collect())),
            Kind::Switch { .. } => None,
            Kind::Reach { .. } => Some(format!("> 0{unit}, or a share in (0 %, 100 %] of the scene's longest side")),
        }
    }

    /// `text` as the command line writes it (`2.5`, `16`, `20%`; a switch `on`/`off`,
    /// `true`/`false`), within the range: the error says what was expected.
    pub fn parse(&self, text: &str) -> Result<Value, String> {
        let text = text.trim();
        let number = |text: &str| text.trim().parse::<f32>().map_err(|_| format!("expected a number, got '{text}'"));
        let value = match self.kind {
            Kind::Reach { .. } => match text.strip_suffix('%') {
                Some(percent) => Value::Share(
                    percent.trim().parse::<f32>().map_err(|_| format!("expected a share such as 20%, got '{text}'"))?
                        / 100.0,
                ),
                None => Value::Number(number(text)?),
            },
            Kind::Number { .. } | Kind::Above { .. } => {
                Value::Number(text.parse().map_err(|_| format!("expected a number, got '{text}'"))?)
            }
            Kind::Count { .. } | Kind::Counts(_) => {
                Value::Count(text.parse().map_err(|_| format!("expected a whole number, got '{text}'"))?)
            }
            Kind::Choice(names) => match names.iter().find(|n| **n == text) {
                Some(name) => Value::Choice(name),
                None => return Err(format!("expected {}, got '{text}'", self.range().unwrap_or_default())),
            },
            Kind::Switch { .. } => Value::Switch(match text {
                "on" | "true" | "True" | "1" => true,
                "off" | "false" | "False" | "0" => false,
                _ => return Err(format!("expected on or off, got '{text}'")),
            }),
        };
        self.check(value).map_err(|e| e.to_string())?;
        Ok(value)
    }

    /// Whether `value` is of its kind and within its range; the error names the flag.
    pub fn check(&self, value: Value) -> Result<(), crate::Error> {
        let fits = match (self.kind, value) {
            (Kind::Number { min, max, open, .. }, Value::Number(x)) => (min..=max).contains(&x) && !(open && x == min),
            (Kind::Above { min, open, .. }, Value::Number(x)) => x.is_finite() && (x > min || (!open && x == min)),
            (Kind::Count { min, max }, Value::Count(n)) => (min..=max).contains(&n),
            (Kind::Counts(counts), Value::Count(n)) => counts.contains(&n),
            (Kind::Choice(names), Value::Choice(name)) => names.contains(&name),
            (Kind::Switch { .. }, Value::Switch(_)) => true,
            (Kind::Reach { .. }, Value::Number(x)) => x.is_finite() && x > 0.0,
            (Kind::Reach { .. }, Value::Share(share)) => share > 0.0 && share <= 1.0,
            _ => false,
        };
        if fits {
            return Ok(());
        }
        Err(crate::Error::OutOfRange {
            setting: self.flag,
            value: value.to_string(),
            expected: self.range().unwrap_or_default(),
        })
    }
}
