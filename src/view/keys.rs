//! The viewer's keys and mouse gestures: one table that the window reads each frame and that
//! docs/options.md lists (generated from it by a test), so the two cannot differ.

use egui::Key;

/// What a key does to the view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Action {
    /// Orbit the eye by 5° along the key's arrow.
    Orbit,
    /// Move the view by 20 px along the key's arrow.
    Pan,
    /// Scale the distance to the target by this factor.
    Zoom(f32),
    /// Back to the data's own camera.
    Reset,
    /// Switch between perspective and orthographic projection.
    Orthographic,
    /// Move the slab by its thickness, backward (−1) or forward (+1).
    Slab(f32),
    /// Turn transparency on or off.
    Transparency,
    /// Start or stop recording a movie.
    Record,
}

/// A row of the table: the keys, whether Shift is held, what they do and the words the docs use.
pub struct Binding {
    /// The keys, any of which acts.
    pub keys: &'static [Key],
    /// Whether Shift must be held (a binding without Shift acts only when Shift is up).
    pub shift: bool,
    /// What they do.
    pub action: Action,
    /// What the docs say.
    pub help: &'static str,
}

const ARROWS: &[Key] = &[Key::ArrowLeft, Key::ArrowRight, Key::ArrowUp, Key::ArrowDown];

/// Every key of the viewer's image (and the page's), when no text field has the keyboard.
pub const KEYS: &[Binding] = &[
    Binding { keys: ARROWS, shift: false, action: Action::Orbit, help: "orbit by 5°" },
    Binding { keys: ARROWS, shift: true, action: Action::Pan, help: "pan by 20 px" },
    Binding { keys: &[Key::Plus, Key::Equals], shift: false, action: Action::Zoom(0.9), help: "zoom in" },
    Binding { keys: &[Key::Minus], shift: false, action: Action::Zoom(1.0 / 0.9), help: "zoom out" },
    Binding { keys: &[Key::R], shift: false, action: Action::Reset, help: "reset the camera" },
    Binding { keys: &[Key::O], shift: false, action: Action::Orthographic, help: "perspective ↔ orthographic" },
    Binding { keys: &[Key::OpenBracket], shift: false, action: Action::Slab(-1.0), help: "move the slab back" },
    Binding { keys: &[Key::CloseBracket], shift: false, action: Action::Slab(1.0), help: "move the slab forward" },
    Binding { keys: &[Key::T], shift: false, action: Action::Transparency, help: "lines seen through ↔ opaque" },
    Binding {
        keys: &[Key::M],
        shift: false,
        action: Action::Record,
        help: "start or stop recording a movie (the viewer: lineao-recording.apng; the page: a WebM)",
    },
];

/// The mouse's gestures over the image, as the window reads them (`App::camera_input`).
pub const MOUSE: &[(&str, &str)] = &[
    ("drag", "orbit"),
    ("right or middle drag, Shift + drag", "pan"),
    ("scroll, pinch", "zoom"),
    ("double-click", "reset the camera"),
    ("drag the divider", "move the split between two methods"),
];

/// The unit step of an arrow key, (x, y) with y down; (0, 0) for any other key.
pub fn arrow(key: Key) -> (f32, f32) {
    match key {
        Key::ArrowLeft => (-1.0, 0.0),
        Key::ArrowRight => (1.0, 0.0),
        Key::ArrowUp => (0.0, -1.0),
        Key::ArrowDown => (0.0, 1.0),
        _ => (0.0, 0.0),
    }
}

/// The actions of the keys pressed this frame, each with its arrow's step. A binding acts
/// with Shift as it says, or with Shift either way where no other binding takes its keys
/// (`+` needs Shift on many keyboards); a binding acts once a frame, the arrows once an arrow.
pub fn pressed(input: &egui::InputState) -> Vec<(Action, (f32, f32))> {
    let shift = input.modifiers.shift;
    let mut actions = Vec::new();
    for binding in KEYS.iter().filter(|b| b.shift == shift || !uses_shift(b)) {
        let keys = binding.keys.iter().filter(|&&key| input.key_pressed(key));
        match binding.action {
            Action::Orbit | Action::Pan => actions.extend(keys.map(|&key| (binding.action, arrow(key)))),
            action => actions.extend(keys.take(1).map(|_| (action, (0.0, 0.0)))),
        }
    }
    actions
}

/// Whether Shift changes what a binding's keys do (another binding has the same keys with Shift).
fn uses_shift(binding: &Binding) -> bool {
    KEYS.iter().any(|other| other.keys == binding.keys && other.shift != binding.shift)
}

/// The keys as the docs write them: `←` `→` `↑` `↓`, `+`, `[`, with `Shift +` where held.
pub fn written(binding: &Binding) -> String {
    let name = |key: Key| match key {
        Key::ArrowLeft => "←",
        Key::ArrowRight => "→",
        Key::ArrowUp => "↑",
        Key::ArrowDown => "↓",
        Key::Minus => "-",
        key => key.symbol_or_name(),
    };
    let keys: Vec<String> = binding.keys.iter().map(|&k| format!("`{}`", name(k))).collect();
    let keys = keys.join(" ");
    if binding.shift { format!("Shift + {keys}") } else { keys }
}
