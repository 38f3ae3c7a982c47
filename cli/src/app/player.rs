//! The viewer's animation clock: which animation plays, the time, the speed, paused or not.
//! Pure logic; the viewer poses the scene when [`Player::advance`] or a key changes the time.

use umbra::scene::anim::{Playing, Rig};

/// One step of `I` / `O` and of an automated run's clock (`--frames`): 1/30 s.
pub const FRAME_STEP: f32 = 1.0 / 30.0;

/// The animation clock.
#[derive(Clone, Debug, PartialEq)]
pub struct Player {
    /// What plays.
    pub playing: Playing,
    /// Time in seconds, within 0..=duration while looping.
    pub time: f32,
    /// Playback speed (1 = real time).
    pub speed: f32,
    /// Paused.
    pub paused: bool,
    names: Vec<String>,
    durations: Vec<f32>,
}

impl Player {
    /// A clock for `rig`: `start` when given (paused there), else the first animation playing
    /// from 0 (the rest pose, paused, for a scene without animations).
    pub fn new(rig: Option<&Rig>, start: Option<(Playing, f32)>) -> Self {
        let anims = rig.map_or(&[][..], |r| &r.animations[..]);
        let mut p = Self {
            playing: Playing::Rest,
            time: 0.0,
            speed: 1.0,
            paused: true,
            names: anims.iter().map(|a| a.name.clone()).collect(),
            durations: anims.iter().map(|a| a.duration()).collect(),
        };
        match start {
            Some((playing, t)) => {
                p.playing = playing;
                p.time = t;
            }
            None => {
                p.playing = Playing::first(rig);
                p.paused = p.playing == Playing::Rest;
            }
        }
        p
    }

    /// Whether there is anything to play.
    pub fn has_animations(&self) -> bool {
        !self.names.is_empty()
    }

    /// Duration of what plays (seconds).
    pub fn duration(&self) -> f32 {
        match self.playing {
            Playing::Rest => 0.0,
            Playing::One(i) => self.durations.get(i).copied().unwrap_or(0.0),
            Playing::All => self.durations.iter().copied().fold(0.0, f32::max),
        }
    }

    /// Advances by `dt` seconds of wall time when playing, looping at the end; returns whether
    /// the time changed.
    pub fn advance(&mut self, dt: f32) -> bool {
        if self.paused || self.playing == Playing::Rest || dt <= 0.0 {
            return false;
        }
        self.time = wrap(self.time + dt * self.speed, self.duration());
        true
    }

    /// Space: play or pause (nothing to play: stays paused).
    pub fn toggle(&mut self) -> String {
        if self.playing == Playing::Rest {
            return "animation: the scene has none playing (R chooses one)".into();
        }
        self.paused = !self.paused;
        self.label()
    }

    /// `I` / `O`: pause and step `frames` frames of [`FRAME_STEP`] (negative: back).
    pub fn step(&mut self, frames: i32) -> String {
        self.paused = true;
        self.time = wrap(self.time + frames as f32 * FRAME_STEP, self.duration());
        self.label()
    }

    /// `Z` / `X`: halve or double the speed (1/16 to 16).
    pub fn scale_speed(&mut self, factor: f32) -> String {
        self.speed = (self.speed * factor).clamp(1.0 / 16.0, 16.0);
        self.label()
    }

    /// `R`: the next animation: 0, 1, …, all, rest, 0 …; time back to 0, playing.
    pub fn next_animation(&mut self) -> String {
        let n = self.names.len();
        self.playing = match self.playing {
            _ if n == 0 => Playing::Rest,
            Playing::One(i) if i + 1 < n => Playing::One(i + 1),
            Playing::One(_) => Playing::All,
            Playing::All => Playing::Rest,
            Playing::Rest => Playing::One(0),
        };
        self.time = 0.0;
        self.paused = self.playing == Playing::Rest;
        self.label()
    }

    /// What plays, for the title and the terminal: name, time / duration, speed, state.
    pub fn label(&self) -> String {
        let name = match self.playing {
            Playing::Rest => return "animation: rest pose".into(),
            Playing::One(i) => format!("{i} '{}'", self.names.get(i).map_or("", |s| s)),
            Playing::All => "all".into(),
        };
        format!(
            "animation: {name} {:.2}/{:.2} s ×{}{}",
            self.time,
            self.duration(),
            self.speed,
            if self.paused { " (paused)" } else { "" }
        )
    }
}

/// `t` looped into 0..=duration (0 for an empty duration).
fn wrap(t: f32, duration: f32) -> f32 {
    if duration <= 0.0 || !t.is_finite() {
        return 0.0;
    }
    t.rem_euclid(duration)
}

#[cfg(test)]
mod tests {
    use super::*;
    use umbra::scene::anim::{Animation, Channel, Interpolation, Keyframes, Property};

    fn rig() -> Rig {
        let anim = |name: &str, end: f32| Animation {
            name: name.into(),
            channels: vec![Channel {
                node: 0,
                property: Property::Translation,
                keys: Keyframes {
                    interpolation: Interpolation::Linear,
                    times: vec![0.0, end],
                    values: vec![0.0; 6],
                    width: 3,
                },
            }],
        };
        Rig {
            animations: vec![anim("Walk", 2.0), anim("Run", 1.0)],
            ..Default::default()
        }
    }

    #[test]
    fn plays_the_first_animation_and_loops() {
        let mut p = Player::new(Some(&rig()), None);
        assert_eq!((p.playing.clone(), p.paused), (Playing::One(0), false));
        assert!(p.advance(1.5));
        assert!(p.advance(1.0));
        assert!((p.time - 0.5).abs() < 1e-6, "{}", p.time);
        p.scale_speed(2.0);
        p.advance(0.5);
        assert!((p.time - 1.5).abs() < 1e-6, "{}", p.time);
        assert!(p.label().contains("'Walk' 1.50/2.00 s ×2"), "{}", p.label());
    }

    #[test]
    fn steps_pause_and_animations_cycle_through_all_and_rest() {
        let mut p = Player::new(Some(&rig()), None);
        p.step(-1);
        assert!(p.paused);
        assert!((p.time - (2.0 - FRAME_STEP)).abs() < 1e-6, "{}", p.time);
        assert!(!p.advance(1.0), "a paused clock stands still");
        let order: Vec<Playing> = (0..4)
            .map(|_| {
                p.next_animation();
                p.playing.clone()
            })
            .collect();
        assert_eq!(
            order,
            [
                Playing::One(1),
                Playing::All,
                Playing::Rest,
                Playing::One(0)
            ]
        );
        assert_eq!(p.time, 0.0);
    }

    #[test]
    fn a_still_scene_stays_at_rest_and_a_given_start_is_paused() {
        let mut p = Player::new(None, None);
        assert!(!p.has_animations());
        assert!(!p.advance(1.0));
        p.toggle();
        assert!(p.paused);
        let p = Player::new(Some(&rig()), Some((Playing::One(1), 0.25)));
        assert_eq!(
            (p.playing.clone(), p.time, p.paused),
            (Playing::One(1), 0.25, true)
        );
    }
}
