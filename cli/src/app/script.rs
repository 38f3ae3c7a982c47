//! Input scripts for the viewer (automation and tests): window sizes, key presses and wheel
//! steps, one every few frames, so a run can drag the sun below the horizon, zoom to the near
//! plane or resize a thousand times and be checked afterwards.
//!
//! A script is a comma-separated list of steps, each optionally repeated with `*N`:
//! `WxH` resizes the window (`0x0` simulates minimising), `key:NAME` presses and releases a key
//! (`up down left right [ ] k + - v h n g j l t comma period f tab c o p space u i z x r f1`,
//! the viewer's own bindings), `wheel:N` scrolls N lines (positive zooms in), `click:X:Y`
//! clicks (picks) at window pixel (X, Y), `ui:NAME` clicks the panel's widget NAME (through
//! egui's own input), `drop:PATH` drops a file on the window, `copy:SRC>DST` copies a file (a
//! model changed on disk, for the viewer's watcher to see) and `wait:reload` holds the script
//! until the next reload is done (at most 30 s).
//! Example: `key:down*40,wheel:1*80,640x360*3,0x0,click:320:200,ui:pcf.3x3`.

/// Key names a script may press (each one of the viewer's bindings).
pub const KEYS: &[&str] = &[
    "up", "down", "left", "right", "[", "]", "k", "+", "-", "v", "h", "n", "g", "j", "l", "t",
    "comma", "period", "f", "tab", "c", "o", "p", "space", "u", "i", "z", "x", "r", "y", "m", "b",
    "f1",
];

/// Most steps one script may expand to (a typo such as `*1000000000` is an error, not a hang).
pub const MAX_STEPS: u64 = 100_000;

/// One scripted input.
#[derive(Clone, Debug, PartialEq)]
pub enum ScriptStep {
    /// Resize the window's inner size (0×0: minimised).
    Resize(u32, u32),
    /// Press and release a key (one of [`KEYS`]).
    Key(&'static str),
    /// Scroll the wheel by this many lines.
    Wheel(f32),
    /// Click (pick) at this window position in pixels.
    Click(f32, f32),
    /// Click the panel's widget of this name (`super::panel::Widgets`).
    Ui(String),
    /// A file dropped on the window.
    Drop(std::path::PathBuf),
    /// Copy a file over another (a model changed on disk).
    Copy(std::path::PathBuf, std::path::PathBuf),
    /// Hold the script until the next reload is done.
    WaitReload,
}

/// Parses one comma-separated item: a step and how many times it repeats.
pub fn parse_item(s: &str) -> Result<(ScriptStep, u32), String> {
    let s = s.trim();
    let (step, times) = match s.rsplit_once('*') {
        Some((a, n)) => (
            a.trim(),
            n.trim()
                .parse::<u32>()
                .map_err(|_| format!("bad repeat count in '{s}'"))?,
        ),
        None => (s, 1),
    };
    if times == 0 || times as u64 > MAX_STEPS {
        return Err(format!("repeat count in '{s}' must be 1..={MAX_STEPS}"));
    }
    let parsed = if let Some(k) = step.strip_prefix("key:") {
        let name = KEYS
            .iter()
            .find(|n| n.eq_ignore_ascii_case(k.trim()))
            .ok_or_else(|| format!("unknown key '{k}' (one of {})", KEYS.join(" ")))?;
        ScriptStep::Key(name)
    } else if let Some(xy) = step.strip_prefix("click:") {
        let (x, y) = xy
            .split_once(':')
            .ok_or_else(|| format!("'{step}' is not click:X:Y"))?;
        let coord = |v: &str| {
            v.trim()
                .parse::<f32>()
                .ok()
                .filter(|v| v.is_finite() && *v >= 0.0)
                .ok_or_else(|| format!("bad click position '{step}'"))
        };
        ScriptStep::Click(coord(x)?, coord(y)?)
    } else if let Some(name) = step.strip_prefix("ui:") {
        if name.trim().is_empty() {
            return Err(format!("'{step}' names no widget"));
        }
        ScriptStep::Ui(name.trim().to_string())
    } else if let Some(path) = step.strip_prefix("drop:") {
        ScriptStep::Drop(path.trim().into())
    } else if let Some(paths) = step.strip_prefix("copy:") {
        let (a, b) = paths
            .split_once('>')
            .ok_or_else(|| format!("'{step}' is not copy:SRC>DST"))?;
        ScriptStep::Copy(a.trim().into(), b.trim().into())
    } else if step == "wait:reload" {
        ScriptStep::WaitReload
    } else if let Some(n) = step.strip_prefix("wheel:") {
        let lines: f32 = n
            .trim()
            .parse()
            .map_err(|_| format!("bad wheel step '{n}'"))?;
        if !lines.is_finite() || lines.abs() > 100.0 {
            return Err(format!("wheel step '{n}' must be within ±100 lines"));
        }
        ScriptStep::Wheel(lines)
    } else {
        let (w, h) = if step == "0x0" {
            (0, 0)
        } else {
            super::parse::parse_size(step).map_err(|e| {
                format!(
                    "{e} (a step is WxH, 0x0, key:NAME, wheel:N, click:X:Y, ui:NAME, \
                         drop:PATH, copy:SRC>DST or wait:reload)"
                )
            })?
        };
        ScriptStep::Resize(w, h)
    };
    Ok((parsed, times))
}

/// The steps of parsed items in order, repeats expanded; an error past [`MAX_STEPS`].
pub fn expand(items: &[(ScriptStep, u32)]) -> Result<Vec<ScriptStep>, String> {
    let total: u64 = items.iter().map(|&(_, n)| n as u64).sum();
    if total > MAX_STEPS {
        return Err(format!("the script has {total} steps; at most {MAX_STEPS}"));
    }
    Ok(items
        .iter()
        .flat_map(|(s, n)| std::iter::repeat_n(s.clone(), *n as usize))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn items_parse_and_expand() {
        let items: Vec<_> = [
            "key:Down*3",
            "wheel:-1.5",
            "640x360*2",
            "0x0",
            "click:10:20.5",
            "ui:pcf.3x3",
            "copy:a.glb>b.glb",
        ]
        .iter()
        .map(|s| parse_item(s).unwrap())
        .collect();
        let steps = expand(&items).unwrap();
        assert_eq!(steps.len(), 10);
        assert_eq!(steps[7], ScriptStep::Click(10.0, 20.5));
        assert_eq!(steps[8], ScriptStep::Ui("pcf.3x3".into()));
        assert_eq!(steps[9], ScriptStep::Copy("a.glb".into(), "b.glb".into()));
        assert_eq!(steps[0], ScriptStep::Key("down"));
        assert_eq!(steps[3], ScriptStep::Wheel(-1.5));
        assert_eq!(steps[5], ScriptStep::Resize(640, 360));
        assert_eq!(steps[6], ScriptStep::Resize(0, 0));
        for bad in [
            "key:q",
            "wheel:x",
            "10x0",
            "5",
            "640x360*0",
            "1x1*100001",
            "99999x1",
            "click:5",
            "click:-1:2",
            "ui:",
            "copy:a.glb",
        ] {
            assert!(parse_item(bad).is_err(), "{bad}");
        }
        let many = [
            (ScriptStep::Wheel(1.0), 60_000),
            (ScriptStep::Wheel(1.0), 60_000),
        ];
        assert!(expand(&many).is_err());
    }
}
