//! The key map: one data table of `(key, context, action, help)` from which
//! the App dispatches, the `?` popup lists keys, the hint line is built and
//! the README's key map is generated (helix `keymap!`, gitui `KeysList`).

use super::camera::ViewKind;
use super::command::{COMMAND_NOTES, usage_rows};
use super::key::{Key, KeyCode};
use super::popup::PopupKind;
use crate::scene::{Block, StateQuantity};

/// Where input goes: each context has its own bindings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Context {
    /// Editing the motion: the default.
    Normal,
    /// After `b`: the next key names a control block to free or fix.
    Block,
    /// Typing a `:` command. Printable characters not bound here are typed.
    Command,
    /// The `?` popup is open.
    Help,
    /// Quitting with unsaved edits: asking whether to discard them.
    Prompt,
    /// Browsing the alternatives an exploration found.
    Explore,
}

impl Context {
    /// Every context, in the order the help lists them.
    pub const ALL: [Context; 6] = [
        Context::Normal,
        Context::Block,
        Context::Command,
        Context::Help,
        Context::Prompt,
        Context::Explore,
    ];

    /// Heading in the help popup and the README.
    pub fn title(self) -> &'static str {
        match self {
            Context::Normal => "editing",
            Context::Block => "after b: control block",
            Context::Command => "command line (:)",
            Context::Help => "popups (?, M, I, A, :notes)",
            Context::Prompt => "quit prompt (unsaved edits)",
            Context::Explore => "alternatives (after X or :explore; other keys as editing)",
        }
    }
}

/// A screen direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Dir {
    Left,
    Right,
    Up,
    Down,
}

impl Dir {
    /// `(right, up)` components, each −1, 0 or 1.
    pub fn unit(self) -> (f64, f64) {
        match self {
            Dir::Left => (-1.0, 0.0),
            Dir::Right => (1.0, 0.0),
            Dir::Up => (0.0, 1.0),
            Dir::Down => (0.0, -1.0),
        }
    }
}

/// Backwards or forwards through a sequence (time, events, bodies, sizes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Sense {
    Back,
    Forward,
}

impl Sense {
    /// −1 or +1.
    pub fn sign(self) -> i64 {
        match self {
            Sense::Back => -1,
            Sense::Forward => 1,
        }
    }
}

/// A UI-level intent. The App turns these into [`crate::edit::Edit`]s or
/// into changes of its own state (camera, mode, prompts).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Action {
    /// Nudge the selected body's current quantity in the view plane; `big`
    /// nudges ten times further.
    Nudge {
        dir: Dir,
        big: bool,
    },
    /// Start (or extend) a count prefix with this digit.
    Count(u8),
    /// Move the current time by one time step.
    Scrub(Sense),
    /// Go to the previous or next collision event.
    Event(Sense),
    /// Select the previous or next body.
    Body(Sense),
    /// Select the previous or next constraint row.
    Constraint(Sense),
    /// Choose the quantity that nudges change.
    Mode(StateQuantity),
    /// Larger (`Forward`) or smaller nudge step.
    StepSize(Sense),
    /// Nail every quantity of the selected body at the current time.
    Nail,
    /// Floating constraint at the selected body's nearest collision.
    Float,
    /// Normal and restitution controls at the nearest event.
    EventControls,
    /// Fix or free the controls at the nearest event.
    ToggleEventControls,
    /// Delete the selected constraint.
    DeleteConstraint,
    /// Wait for a block letter (the `b` prefix).
    BlockPrefix,
    /// Free or fix a control block of the selected body.
    ToggleBlock(Block),
    /// Leave a prefix or prompt without doing anything.
    Cancel,
    /// Iterate updates until the constraints are met.
    Settle,
    Undo,
    Redo,
    /// Start or stop animating the current time.
    Play,
    /// Switch to one of the views.
    View(ViewKind),
    /// Turn the orbit view about the vertical.
    Yaw(Sense),
    /// Raise or lower the orbit view's eye.
    Pitch(Sense),
    /// Move the visible window.
    Pan(Dir),
    /// Zoom in (`Forward`) or out.
    Zoom(Sense),
    /// Fit the scene and reset the orbit angles.
    ResetView,
    /// Open the `:` command line.
    CommandLine,
    /// Run the command line.
    CommandRun,
    /// Delete the last character typed.
    CommandBackspace,
    /// Clear the command line.
    CommandClear,
    /// Open a popup: the key help, the message log.
    Popup(PopupKind),
    /// Scroll the popup.
    Scroll(Sense),
    /// Show or hide the motion before the last edit.
    ToggleGhost,
    /// Explore alternatives around the motion in the background.
    Explore,
    /// Show the next or previous alternative.
    Alternative(Sense),
    /// Take the alternative shown; with `settle`, settle from it at once.
    AcceptAlternative {
        settle: bool,
    },
    /// Measure the accuracy settings around the current one.
    Accuracy,
    /// Make the setting chosen in the accuracy popup the scene's.
    PickAccuracy,
    /// Quit (asks first when there are unsaved edits).
    Quit,
    /// Quit and discard unsaved edits (from the prompt).
    ConfirmQuit,
    /// Save, then quit (from the prompt).
    SaveQuit,
}

impl Action {
    /// Whether a count prefix repeats or scales this action.
    pub fn takes_count(self) -> bool {
        matches!(
            self,
            Action::Nudge { .. }
                | Action::Scrub(_)
                | Action::Event(_)
                | Action::Body(_)
                | Action::Constraint(_)
                | Action::StepSize(_)
                | Action::Undo
                | Action::Redo
                | Action::Yaw(_)
                | Action::Pitch(_)
                | Action::Pan(_)
                | Action::Zoom(_)
                | Action::Scroll(_)
        )
    }

    /// The variant's name, payload ignored. The match is exhaustive, so a
    /// new action cannot be added without naming it here.
    pub fn kind(self) -> &'static str {
        match self {
            Action::Nudge { .. } => "Nudge",
            Action::Count(_) => "Count",
            Action::Scrub(_) => "Scrub",
            Action::Event(_) => "Event",
            Action::Body(_) => "Body",
            Action::Constraint(_) => "Constraint",
            Action::Mode(_) => "Mode",
            Action::StepSize(_) => "StepSize",
            Action::Nail => "Nail",
            Action::Float => "Float",
            Action::EventControls => "EventControls",
            Action::ToggleEventControls => "ToggleEventControls",
            Action::DeleteConstraint => "DeleteConstraint",
            Action::BlockPrefix => "BlockPrefix",
            Action::ToggleBlock(_) => "ToggleBlock",
            Action::Cancel => "Cancel",
            Action::Settle => "Settle",
            Action::Undo => "Undo",
            Action::Redo => "Redo",
            Action::Play => "Play",
            Action::View(_) => "View",
            Action::Yaw(_) => "Yaw",
            Action::Pitch(_) => "Pitch",
            Action::Pan(_) => "Pan",
            Action::Zoom(_) => "Zoom",
            Action::ResetView => "ResetView",
            Action::CommandLine => "CommandLine",
            Action::CommandRun => "CommandRun",
            Action::CommandBackspace => "CommandBackspace",
            Action::CommandClear => "CommandClear",
            Action::Popup(_) => "Popup",
            Action::Scroll(_) => "Scroll",
            Action::ToggleGhost => "ToggleGhost",
            Action::Explore => "Explore",
            Action::Alternative(_) => "Alternative",
            Action::AcceptAlternative { .. } => "AcceptAlternative",
            Action::Accuracy => "Accuracy",
            Action::PickAccuracy => "PickAccuracy",
            Action::Quit => "Quit",
            Action::ConfirmQuit => "ConfirmQuit",
            Action::SaveQuit => "SaveQuit",
        }
    }

    /// One action of every kind (for table-consistency tests).
    pub fn one_of_each() -> Vec<Action> {
        vec![
            Action::Nudge {
                dir: Dir::Left,
                big: false,
            },
            Action::Count(5),
            Action::Scrub(Sense::Back),
            Action::Event(Sense::Back),
            Action::Body(Sense::Back),
            Action::Constraint(Sense::Back),
            Action::Mode(StateQuantity::Position),
            Action::StepSize(Sense::Back),
            Action::Nail,
            Action::Float,
            Action::EventControls,
            Action::ToggleEventControls,
            Action::DeleteConstraint,
            Action::BlockPrefix,
            Action::ToggleBlock(Block::Position),
            Action::Cancel,
            Action::Settle,
            Action::Undo,
            Action::Redo,
            Action::Play,
            Action::View(ViewKind::Front),
            Action::Yaw(Sense::Back),
            Action::Pitch(Sense::Back),
            Action::Pan(Dir::Left),
            Action::Zoom(Sense::Back),
            Action::ResetView,
            Action::CommandLine,
            Action::CommandRun,
            Action::CommandBackspace,
            Action::CommandClear,
            Action::Popup(PopupKind::Help),
            Action::Scroll(Sense::Back),
            Action::ToggleGhost,
            Action::Explore,
            Action::Alternative(Sense::Back),
            Action::AcceptAlternative { settle: false },
            Action::Accuracy,
            Action::PickAccuracy,
            Action::Quit,
            Action::ConfirmQuit,
            Action::SaveQuit,
        ]
    }
}

/// One row of the key map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Binding {
    pub key: Key,
    pub context: Context,
    pub action: Action,
    /// What the key does, for the help popup and the README.
    pub help: &'static str,
    /// Label in the hint line, if this key is advertised there. Keys with
    /// the same label are shown together (`hjkl nudge`).
    pub hint: Option<&'static str>,
}

const fn bind(key: Key, context: Context, action: Action, help: &'static str) -> Binding {
    Binding {
        key,
        context,
        action,
        help,
        hint: None,
    }
}

const fn hint(
    key: Key,
    context: Context,
    action: Action,
    help: &'static str,
    label: &'static str,
) -> Binding {
    Binding {
        key,
        context,
        action,
        help,
        hint: Some(label),
    }
}

const fn ch(c: char) -> Key {
    Key::char(c)
}

const fn code(c: KeyCode) -> Key {
    Key::new(c)
}

use Context::{
    Block as Blk, Command as Cmd, Explore as Exp, Help as Hlp, Normal as Nrm, Prompt as Prm,
};

const fn nudge(dir: Dir, big: bool) -> Action {
    Action::Nudge { dir, big }
}

/// The key map. Order matters only for display: the help popup, the hint
/// line and the README list keys in this order.
#[rustfmt::skip]
pub static KEYMAP: &[Binding] = &[
    // Nudging the selected body.
    hint(ch('h'), Nrm, nudge(Dir::Left, false), "nudge left in the view plane", "nudge"),
    hint(ch('j'), Nrm, nudge(Dir::Down, false), "nudge down in the view plane", "nudge"),
    hint(ch('k'), Nrm, nudge(Dir::Up, false), "nudge up in the view plane", "nudge"),
    hint(ch('l'), Nrm, nudge(Dir::Right, false), "nudge right in the view plane", "nudge"),
    bind(code(KeyCode::Left), Nrm, nudge(Dir::Left, false), "nudge left in the view plane"),
    bind(code(KeyCode::Down), Nrm, nudge(Dir::Down, false), "nudge down in the view plane"),
    bind(code(KeyCode::Up), Nrm, nudge(Dir::Up, false), "nudge up in the view plane"),
    bind(code(KeyCode::Right), Nrm, nudge(Dir::Right, false), "nudge right in the view plane"),
    bind(ch('H'), Nrm, nudge(Dir::Left, true), "nudge left, 10× the step"),
    bind(ch('J'), Nrm, nudge(Dir::Down, true), "nudge down, 10× the step"),
    bind(ch('K'), Nrm, nudge(Dir::Up, true), "nudge up, 10× the step"),
    bind(ch('L'), Nrm, nudge(Dir::Right, true), "nudge right, 10× the step"),
    bind(code(KeyCode::Left).shift(), Nrm, nudge(Dir::Left, true), "nudge left, 10× the step"),
    bind(code(KeyCode::Down).shift(), Nrm, nudge(Dir::Down, true), "nudge down, 10× the step"),
    bind(code(KeyCode::Up).shift(), Nrm, nudge(Dir::Up, true), "nudge up, 10× the step"),
    bind(code(KeyCode::Right).shift(), Nrm, nudge(Dir::Right, true), "nudge right, 10× the step"),
    bind(ch('5'), Nrm, Action::Count(5), "count: 5l nudges 5 steps (5-9 start a count)"),
    bind(ch('6'), Nrm, Action::Count(6), "count: 5l nudges 5 steps (5-9 start a count)"),
    bind(ch('7'), Nrm, Action::Count(7), "count: 5l nudges 5 steps (5-9 start a count)"),
    bind(ch('8'), Nrm, Action::Count(8), "count: 5l nudges 5 steps (5-9 start a count)"),
    bind(ch('9'), Nrm, Action::Count(9), "count: 5l nudges 5 steps (5-9 start a count)"),
    hint(ch('P'), Nrm, Action::Mode(StateQuantity::Position), "nudge position (default)", "mode"),
    hint(ch('O'), Nrm, Action::Mode(StateQuantity::Orientation), "nudge orientation (h/l roll, j/k tilt)", "mode"),
    hint(ch('V'), Nrm, Action::Mode(StateQuantity::Velocity), "nudge velocity", "mode"),
    hint(ch('W'), Nrm, Action::Mode(StateQuantity::AngularVelocity), "nudge angular velocity (keys as for orientation)", "mode"),
    bind(ch('+'), Nrm, Action::StepSize(Sense::Forward), "larger nudge step (1-2-5 ladder)"),
    bind(ch('-'), Nrm, Action::StepSize(Sense::Back), "smaller nudge step (1-2-5 ladder)"),
    // Time, events, bodies.
    hint(ch('['), Nrm, Action::Scrub(Sense::Back), "time back one step (1% of the motion)", "time"),
    hint(ch(']'), Nrm, Action::Scrub(Sense::Forward), "time forward one step (1% of the motion)", "time"),
    bind(ch(','), Nrm, Action::Scrub(Sense::Back), "time back one step (1% of the motion)"),
    bind(ch('.'), Nrm, Action::Scrub(Sense::Forward), "time forward one step (1% of the motion)"),
    hint(ch('{'), Nrm, Action::Event(Sense::Back), "previous collision event", "event"),
    hint(ch('}'), Nrm, Action::Event(Sense::Forward), "next collision event", "event"),
    bind(ch('N'), Nrm, Action::Event(Sense::Back), "previous collision event"),
    bind(ch('n'), Nrm, Action::Event(Sense::Forward), "next collision event"),
    hint(code(KeyCode::Tab), Nrm, Action::Body(Sense::Forward), "select the next body", "body"),
    bind(code(KeyCode::Tab).shift(), Nrm, Action::Body(Sense::Back), "select the previous body"),
    bind(ch('p'), Nrm, Action::Play, "play / pause the motion"),
    bind(ch(' '), Nrm, Action::Play, "play / pause the motion"),
    // Constraints and controls.
    hint(ch('a'), Nrm, Action::Nail, "nail all four quantities now (:nail for a subset)", "nail"),
    bind(ch('f'), Nrm, Action::Float, "floating constraint at the nearest collision"),
    bind(ch('e'), Nrm, Action::EventControls, "normal + restitution controls at the nearest event"),
    bind(ch('E'), Nrm, Action::ToggleEventControls, "fix/free the controls at the nearest event"),
    bind(ch('c'), Nrm, Action::Constraint(Sense::Forward), "select the next constraint row"),
    bind(ch('C'), Nrm, Action::Constraint(Sense::Back), "select the previous constraint row"),
    bind(ch('x'), Nrm, Action::DeleteConstraint, "delete the selected constraint"),
    bind(ch('b'), Nrm, Action::BlockPrefix, "free/fix a block of the body (then p o v w m i)"),
    bind(ch('s'), Nrm, Action::Settle, "settle: iterate until constraints are met"),
    hint(ch('u'), Nrm, Action::Undo, "undo", "undo"),
    bind(ch('r').ctrl(), Nrm, Action::Redo, "redo"),
    // Camera.
    bind(ch('1'), Nrm, Action::View(ViewKind::Front), "front view (x right, z up)"),
    bind(ch('2'), Nrm, Action::View(ViewKind::Side), "side view (y right, z up)"),
    bind(ch('3'), Nrm, Action::View(ViewKind::Top), "top view (x right, y up)"),
    bind(ch('4'), Nrm, Action::View(ViewKind::DEFAULT_ORBIT), "orbit view"),
    bind(ch('<'), Nrm, Action::Yaw(Sense::Back), "orbit: turn left"),
    bind(ch('>'), Nrm, Action::Yaw(Sense::Forward), "orbit: turn right"),
    bind(ch('^'), Nrm, Action::Pitch(Sense::Forward), "orbit: look from higher"),
    bind(ch('v'), Nrm, Action::Pitch(Sense::Back), "orbit: look from lower"),
    bind(code(KeyCode::Left).ctrl(), Nrm, Action::Pan(Dir::Left), "pan left"),
    bind(code(KeyCode::Down).ctrl(), Nrm, Action::Pan(Dir::Down), "pan down"),
    bind(code(KeyCode::Up).ctrl(), Nrm, Action::Pan(Dir::Up), "pan up"),
    bind(code(KeyCode::Right).ctrl(), Nrm, Action::Pan(Dir::Right), "pan right"),
    bind(ch('h').alt(), Nrm, Action::Pan(Dir::Left), "pan left"),
    bind(ch('j').alt(), Nrm, Action::Pan(Dir::Down), "pan down"),
    bind(ch('k').alt(), Nrm, Action::Pan(Dir::Up), "pan up"),
    bind(ch('l').alt(), Nrm, Action::Pan(Dir::Right), "pan right"),
    bind(ch('z'), Nrm, Action::Zoom(Sense::Forward), "zoom in"),
    bind(ch('='), Nrm, Action::Zoom(Sense::Forward), "zoom in"),
    bind(ch('Z'), Nrm, Action::Zoom(Sense::Back), "zoom out"),
    bind(ch('_'), Nrm, Action::Zoom(Sense::Back), "zoom out"),
    bind(ch('0'), Nrm, Action::ResetView, "fit the scene, reset the orbit"),
    bind(ch('g'), Nrm, Action::ToggleGhost, "show/hide the motion before the last edit"),
    bind(ch('X'), Nrm, Action::Explore, "explore alternatives when a drag is blocked"),
    // The rest.
    bind(ch(':'), Nrm, Action::CommandLine, "command line (:help lists commands)"),
    hint(ch('?'), Nrm, Action::Popup(PopupKind::Help), "this help", "help"),
    bind(ch('M'), Nrm, Action::Popup(PopupKind::Messages), "every message so far (:messages)"),
    bind(ch('I'), Nrm, Action::Popup(PopupKind::Jacobian), "how each free control moves the body (:jacobian)"),
    bind(ch('A'), Nrm, Action::Accuracy, "cost and error of nearby accuracies (:accuracy)"),
    hint(ch('q'), Nrm, Action::Quit, "quit (asks when there are unsaved edits)", "quit"),
    bind(code(KeyCode::Esc), Nrm, Action::Cancel, "cancel a count, a drag or a settle; never quits"),
    // After `b`.
    hint(ch('p'), Blk, Action::ToggleBlock(Block::Position), "initial position", "block"),
    hint(ch('o'), Blk, Action::ToggleBlock(Block::Orientation), "initial orientation", "block"),
    hint(ch('v'), Blk, Action::ToggleBlock(Block::Velocity), "initial velocity", "block"),
    hint(ch('w'), Blk, Action::ToggleBlock(Block::AngularVelocity), "initial angular velocity", "block"),
    hint(ch('m'), Blk, Action::ToggleBlock(Block::Mass), "mass", "block"),
    hint(ch('i'), Blk, Action::ToggleBlock(Block::Inertia), "principal inertia", "block"),
    hint(code(KeyCode::Esc), Blk, Action::Cancel, "cancel", "cancel"),
    // Command line.
    hint(code(KeyCode::Enter), Cmd, Action::CommandRun, "run the command", "run"),
    hint(code(KeyCode::Esc), Cmd, Action::Cancel, "cancel", "cancel"),
    hint(code(KeyCode::Backspace), Cmd, Action::CommandBackspace, "delete a character (on empty: cancel)", "delete"),
    bind(ch('u').ctrl(), Cmd, Action::CommandClear, "clear the line"),
    // Popups.
    hint(ch('j'), Hlp, Action::Scroll(Sense::Forward), "scroll down", "scroll"),
    hint(ch('k'), Hlp, Action::Scroll(Sense::Back), "scroll up", "scroll"),
    bind(code(KeyCode::Down), Hlp, Action::Scroll(Sense::Forward), "scroll down"),
    bind(code(KeyCode::Up), Hlp, Action::Scroll(Sense::Back), "scroll up"),
    bind(code(KeyCode::PageDown), Hlp, Action::Scroll(Sense::Forward), "scroll down"),
    bind(code(KeyCode::PageUp), Hlp, Action::Scroll(Sense::Back), "scroll up"),
    bind(code(KeyCode::Enter), Hlp, Action::PickAccuracy, "pick the setting chosen (A; u undoes)"),
    hint(ch('?'), Hlp, Action::Cancel, "close", "close"),
    bind(ch('q'), Hlp, Action::Cancel, "close"),
    bind(code(KeyCode::Esc), Hlp, Action::Cancel, "close"),
    // Quit prompt.
    hint(ch('y'), Prm, Action::ConfirmQuit, "quit, discarding unsaved edits", "discard"),
    hint(ch('w'), Prm, Action::SaveQuit, "save, then quit", "save"),
    hint(ch('n'), Prm, Action::Cancel, "keep editing", "cancel"),
    bind(code(KeyCode::Esc), Prm, Action::Cancel, "keep editing"),
    // Browsing alternatives.
    hint(ch('j'), Exp, Action::Alternative(Sense::Forward), "next alternative", "others"),
    hint(ch('k'), Exp, Action::Alternative(Sense::Back), "previous alternative", "others"),
    bind(code(KeyCode::Tab), Exp, Action::Alternative(Sense::Forward), "next alternative"),
    bind(code(KeyCode::Tab).shift(), Exp, Action::Alternative(Sense::Back), "previous alternative"),
    hint(code(KeyCode::Enter), Exp, Action::AcceptAlternative { settle: false }, "take the alternative shown (u undoes)", "take"),
    hint(ch('S'), Exp, Action::AcceptAlternative { settle: true }, "take it and settle from it (u undoes)", "take+settle"),
    hint(code(KeyCode::Esc), Exp, Action::Cancel, "dismiss the alternatives", "dismiss"),
];

/// The action bound to `key` in `context`.
pub fn lookup(context: Context, key: Key) -> Option<Action> {
    let key = key.normalized();
    KEYMAP
        .iter()
        .find(|b| b.context == context && b.key == key)
        .map(|b| b.action)
}

/// A key as shown in hints: vim notation without the angle brackets
/// (`Tab`, `S-Left`, `C-r`).
pub fn short_label(key: Key) -> String {
    let s = key.to_string();
    match s.strip_prefix('<').and_then(|s| s.strip_suffix('>')) {
        Some("lt") => "<".to_string(),
        Some(inner) => inner.to_string(),
        None => s,
    }
}

/// The hint line for `context`: advertised keys grouped by label, in table
/// order, as many groups as fit in `width` columns.
pub fn hints(context: Context, width: usize) -> String {
    let mut groups: Vec<(&'static str, Vec<String>)> = Vec::new();
    for b in KEYMAP.iter().filter(|b| b.context == context) {
        let Some(label) = b.hint else { continue };
        match groups.iter_mut().find(|(l, _)| *l == label) {
            Some((_, keys)) => keys.push(short_label(b.key)),
            None => groups.push((label, vec![short_label(b.key)])),
        }
    }
    let mut out = String::new();
    for (label, keys) in groups {
        let joined = if keys.iter().all(|k| k.chars().count() == 1) {
            keys.concat()
        } else {
            keys.join("/")
        };
        let item = format!("{joined} {label}");
        let sep = if out.is_empty() { 0 } else { 2 };
        if out.chars().count() + sep + item.chars().count() > width {
            break;
        }
        if sep > 0 {
            out.push_str("  ");
        }
        out.push_str(&item);
    }
    out
}

/// One row of the help: the keys of one context that share a help text.
#[derive(Debug, Clone, PartialEq)]
pub struct HelpRow {
    pub context: Context,
    /// Keys in vim notation, e.g. `["h", "<Left>"]`.
    pub keys: Vec<String>,
    pub help: &'static str,
}

/// The help rows, grouped: within a context, keys with the same help text
/// share a row.
pub fn help_rows() -> Vec<HelpRow> {
    let mut rows: Vec<HelpRow> = Vec::new();
    for context in Context::ALL {
        for b in KEYMAP.iter().filter(|b| b.context == context) {
            match rows
                .iter_mut()
                .find(|r| r.context == context && r.help == b.help)
            {
                Some(row) => row.keys.push(b.key.to_string()),
                None => rows.push(HelpRow {
                    context,
                    keys: vec![b.key.to_string()],
                    help: b.help,
                }),
            }
        }
    }
    rows
}

/// The key map as Markdown: the README's "Keys" section between its
/// `<!-- keys:begin -->` and `<!-- keys:end -->` markers.
pub fn markdown() -> String {
    let mut out = String::from(
        "## Keys\n\nGenerated from `src/tui/keymap.rs` (`nudge::tui::keymap_markdown`); \
         the `?` popup shows the same table.\n\
         Keys are in vim notation, the notation key scripts use: `<S-Left>` is Shift+Left, \
         `<C-r>` is Ctrl+R, `<A-h>` is Alt+H, `<lt>` is `<`.\n\n\
         Nudges move the selected body's current quantity (modes `P` `O` `V` `W`) in the plane \
         of the screen, along the camera's right and up directions; for orientation and angular \
         velocity, `h`/`l` roll about the line of sight and `j`/`k` tilt about the screen's \
         horizontal. A count (`5l`, `50]`) starts with a digit 5-9, because 1-4 choose views; \
         once started, any digit extends it.\n",
    );
    for context in Context::ALL {
        out.push_str(&format!(
            "\n### {}\n\n| keys | action |\n|---|---|\n",
            context.title()
        ));
        for row in help_rows().into_iter().filter(|r| r.context == context) {
            let keys: Vec<String> = row
                .keys
                .iter()
                .map(|k| format!("`{}`", k.replace('|', "\\|")))
                .collect();
            out.push_str(&format!(
                "| {} | {} |\n",
                keys.join(" "),
                row.help.replace('|', "\\|")
            ));
        }
        if context == Context::Command {
            out.push_str("| any other character | typed into the command |\n");
        }
    }
    out.push_str("\n### commands (:)\n\n| command | does |\n|---|---|\n");
    for (cmd, does) in usage_rows() {
        out.push_str(&format!("| `{}` | {} |\n", cmd.replace('|', "\\|"), does));
    }
    out.push('\n');
    for note in COMMAND_NOTES {
        out.push_str(&format!("{note}  \n"));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashSet;

    #[test]
    fn no_key_is_bound_twice_in_one_context() {
        let mut seen = HashSet::new();
        for b in KEYMAP {
            assert!(
                seen.insert((b.context, b.key)),
                "{} bound twice in {:?}",
                b.key,
                b.context
            );
        }
    }

    #[test]
    fn every_key_in_the_table_is_normalised() {
        for b in KEYMAP {
            assert_eq!(b.key, b.key.normalized(), "{} is not in normal form", b.key);
        }
    }

    #[test]
    fn every_action_kind_is_bound_with_help() {
        let bound: HashSet<&str> = KEYMAP.iter().map(|b| b.action.kind()).collect();
        for a in Action::one_of_each() {
            assert!(bound.contains(a.kind()), "{} has no key", a.kind());
        }
        for b in KEYMAP {
            assert!(!b.help.trim().is_empty(), "{} has no help text", b.key);
        }
    }

    /// The help popup shows a key column and the help on one line at 80
    /// columns; longer texts would be cut.
    #[test]
    fn help_texts_fit_the_popup_at_80_columns() {
        for b in KEYMAP {
            assert!(b.help.chars().count() <= 50, "{}: {}", b.key, b.help);
        }
        for (cmd, does) in usage_rows() {
            assert!(
                cmd.chars().count() <= 26 && does.chars().count() <= 44,
                "{cmd}: {does}"
            );
        }
        for note in COMMAND_NOTES {
            assert!(note.chars().count() <= 74, "{note}");
        }
    }

    #[test]
    fn one_of_each_lists_each_kind_once() {
        let all = Action::one_of_each();
        let kinds: HashSet<&str> = all.iter().map(|a| a.kind()).collect();
        assert_eq!(kinds.len(), all.len());
    }

    #[test]
    fn every_context_has_a_way_out() {
        for context in [
            Context::Block,
            Context::Command,
            Context::Help,
            Context::Prompt,
            Context::Explore,
        ] {
            assert_eq!(
                lookup(context, Key::new(KeyCode::Esc)),
                Some(Action::Cancel),
                "{context:?}"
            );
        }
    }

    #[test]
    fn help_rows_cover_every_binding() {
        let rows = help_rows();
        for b in KEYMAP {
            let key = b.key.to_string();
            assert!(
                rows.iter()
                    .any(|r| r.context == b.context && r.keys.contains(&key)),
                "{key} missing"
            );
        }
    }

    #[test]
    fn hints_fit_the_width_and_group_keys() {
        let line = hints(Context::Normal, 80);
        assert!(line.chars().count() <= 80, "{line}");
        assert_eq!(
            line,
            "hjkl nudge  POVW mode  [] time  {} event  Tab body  a nail  u undo  ? help"
        );
        assert_eq!(hints(Context::Normal, 3), "");
        assert_eq!(hints(Context::Prompt, 80), "y discard  w save  n cancel");
    }

    #[test]
    fn lookup_normalises_the_key() {
        let shifted_char = Key {
            code: KeyCode::Char('L'),
            mods: super::super::key::Mods {
                shift: true,
                ..Default::default()
            },
        };
        assert_eq!(
            lookup(Context::Normal, shifted_char),
            Some(Action::Nudge {
                dir: Dir::Right,
                big: true
            })
        );
    }

    /// The README's key map is this table: regenerate it with
    /// `NUDGE_BLESS=1 cargo test docs_keys` after changing a binding.
    #[test]
    fn readme_keys_section_is_up_to_date() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/README.md");
        let readme = std::fs::read_to_string(path).unwrap_or_default();
        let (begin, end) = ("<!-- keys:begin -->\n", "<!-- keys:end -->");
        let (Some(a), Some(b)) = (readme.find(begin), readme.find(end)) else {
            panic!("README.md lacks the {begin:?} … {end:?} markers");
        };
        let current = &readme[a + begin.len()..b];
        if current != markdown() {
            if std::env::var_os("NUDGE_BLESS").is_some() {
                let fresh = format!(
                    "{}{}{}",
                    &readme[..a + begin.len()],
                    markdown(),
                    &readme[b..]
                );
                std::fs::write(path, fresh).expect("write README.md");
            } else {
                panic!("README.md key map is stale: rerun with NUDGE_BLESS=1");
            }
        }
    }
}
