//! The viewer's key bindings: what each key does, and the names a script presses them by.

use crate::app::actions::Action;
use crate::app::controller::MoveKey;
use winit::keyboard::KeyCode;

/// The animation keys (and the panel's animation buttons).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AnimKey {
    /// Play or pause.
    Toggle,
    /// Step this many frames (1/30 s each).
    Step(i32),
    /// Speed ×.
    Speed(f32),
    /// Next animation.
    Next,
}

/// What a key does in the viewer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum KeyAction {
    /// A view setting.
    Setting(Action),
    /// The light the shadow views show.
    ShadowLight,
    /// Fly movement (held).
    Move(MoveKey),
    /// Frame the scene.
    Frame,
    /// Orbit ↔ fly.
    ToggleFly,
    /// Next glTF camera.
    NextCamera,
    /// Perspective ↔ orthographic.
    ToggleOrthographic,
    /// Save a screenshot.
    Screenshot,
    /// Animation.
    Anim(AnimKey),
    /// Show or hide the panel.
    TogglePanel,
    /// Quit.
    Quit,
}

/// The key a script names (`crate::app::script::KEYS`).
pub fn script_key(name: &str) -> Option<KeyCode> {
    Some(match name {
        "up" => KeyCode::ArrowUp,
        "down" => KeyCode::ArrowDown,
        "left" => KeyCode::ArrowLeft,
        "right" => KeyCode::ArrowRight,
        "[" => KeyCode::BracketLeft,
        "]" => KeyCode::BracketRight,
        "k" => KeyCode::KeyK,
        "+" => KeyCode::Equal,
        "-" => KeyCode::Minus,
        "v" => KeyCode::KeyV,
        "h" => KeyCode::KeyH,
        "n" => KeyCode::KeyN,
        "g" => KeyCode::KeyG,
        "j" => KeyCode::KeyJ,
        "l" => KeyCode::KeyL,
        "f" => KeyCode::KeyF,
        "tab" => KeyCode::Tab,
        "c" => KeyCode::KeyC,
        "o" => KeyCode::KeyO,
        "p" => KeyCode::KeyP,
        "t" => KeyCode::KeyT,
        "comma" => KeyCode::Comma,
        "period" => KeyCode::Period,
        "space" => KeyCode::Space,
        "u" => KeyCode::KeyU,
        "i" => KeyCode::KeyI,
        "z" => KeyCode::KeyZ,
        "x" => KeyCode::KeyX,
        "r" => KeyCode::KeyR,
        "y" => KeyCode::KeyY,
        "m" => KeyCode::KeyM,
        "b" => KeyCode::KeyB,
        "f1" => KeyCode::F1,
        _ => return None,
    })
}

/// What `code` does (None: nothing).
pub fn key_action(code: KeyCode) -> Option<KeyAction> {
    use KeyAction::*;
    Some(match code {
        KeyCode::ArrowLeft => Setting(Action::SunLeft),
        KeyCode::ArrowRight => Setting(Action::SunRight),
        KeyCode::ArrowUp => Setting(Action::SunUp),
        KeyCode::ArrowDown => Setting(Action::SunDown),
        KeyCode::BracketLeft => Setting(Action::MapSmaller),
        KeyCode::BracketRight => Setting(Action::MapLarger),
        KeyCode::KeyK => Setting(Action::CyclePcf),
        KeyCode::Equal | KeyCode::NumpadAdd => Setting(Action::BiasUp),
        KeyCode::Minus | KeyCode::NumpadSubtract => Setting(Action::BiasDown),
        KeyCode::KeyV => Setting(Action::CycleView),
        KeyCode::KeyH => Setting(Action::ToggleShadows),
        KeyCode::KeyN => Setting(Action::CycleCascades),
        KeyCode::KeyG => Setting(Action::ToggleDepthFit),
        KeyCode::KeyJ => Setting(Action::ToggleSoft),
        KeyCode::KeyT => Setting(Action::CycleTonemap),
        KeyCode::KeyY => Setting(Action::ToggleFxaa),
        KeyCode::KeyM => Setting(Action::ToggleMethod),
        KeyCode::KeyB => Setting(Action::ToggleContact),
        KeyCode::Period => Setting(Action::ExposureUp),
        KeyCode::Comma => Setting(Action::ExposureDown),
        KeyCode::KeyL => ShadowLight,
        KeyCode::KeyW => Move(MoveKey::W),
        KeyCode::KeyA => Move(MoveKey::A),
        KeyCode::KeyS => Move(MoveKey::S),
        KeyCode::KeyD => Move(MoveKey::D),
        KeyCode::KeyQ => Move(MoveKey::Q),
        KeyCode::KeyE => Move(MoveKey::E),
        KeyCode::ShiftLeft | KeyCode::ShiftRight => Move(MoveKey::Shift),
        KeyCode::KeyF => Frame,
        KeyCode::Tab => ToggleFly,
        KeyCode::KeyC => NextCamera,
        KeyCode::KeyO => ToggleOrthographic,
        KeyCode::KeyP => Screenshot,
        KeyCode::Space => Anim(AnimKey::Toggle),
        KeyCode::KeyU => Anim(AnimKey::Step(-1)),
        KeyCode::KeyI => Anim(AnimKey::Step(1)),
        KeyCode::KeyZ => Anim(AnimKey::Speed(0.5)),
        KeyCode::KeyX => Anim(AnimKey::Speed(2.0)),
        KeyCode::KeyR => Anim(AnimKey::Next),
        KeyCode::F1 => TogglePanel,
        KeyCode::Escape => Quit,
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_script_key_is_bound() {
        for name in crate::app::script::KEYS {
            let code = script_key(name).unwrap_or_else(|| panic!("no key for '{name}'"));
            assert!(key_action(code).is_some(), "'{name}' does nothing");
        }
    }
}
