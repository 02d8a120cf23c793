//! BVH reader: bytes → [`Bvh`] plus the warnings for what was tolerated.
//!
//! Grammar accepted (keywords in any letter case, tokens separated by spaces, tabs, CR or LF):
//!
//! ```text
//! HIERARCHY
//! ROOT <name>            (one or more roots; the name is the rest of the line)
//! {
//!   OFFSET x y z         (OFFSET and CHANNELS both required, in either order,
//!   CHANNELS n c1 .. cn   before the joint's children; channel names on one line)
//!   JOINT <name> { ... } (any number of children)
//!   End Site { OFFSET x y z }
//! }
//! MOTION
//! Frames: N
//! Frame Time: t          (t > 0 seconds)
//! v1 v2 ... vC           (N lines, exactly C = Σ n values each)
//! ```
//!
//! The hierarchy is small and read with a token lexer. The MOTION block, which is nearly all of
//! a file, is read in place over the byte slice: one pass finds each value's bytes and hands
//! them to `str::parse::<f64>` (an Eisel–Lemire parser), writing into a `Vec<f64>` sized
//! `frames × channel_count` up front, so parsing time is number-conversion time.

use std::path::Path;

use glam::DVec3;

use super::{
    Bvh, BvhError, BvhJoint, BvhWarning, Channel, MAX_ANGLE_DEG, MAX_DEPTH, MAX_JOINTS,
    MAX_LENGTH_UNITS,
};

/// The six channel kinds, in the order used to look names up.
const ALL_CHANNELS: [Channel; 6] = [
    Channel::Xposition,
    Channel::Yposition,
    Channel::Zposition,
    Channel::Xrotation,
    Channel::Yrotation,
    Channel::Zrotation,
];

/// Longest token text quoted in an error message; longer tokens are cut with "…".
const QUOTE_MAX: usize = 40;

/// Reads a BVH file's content.
///
/// Returns the data and the warnings for tolerated oddities (motion lines beyond the declared
/// frame count, blank lines inside the motion). Any malformed input gives a [`BvhError`] naming
/// the line, what was expected and what was found; this function does not panic.
pub fn parse(bytes: &[u8]) -> Result<(Bvh, Vec<BvhWarning>), BvhError> {
    let text = match std::str::from_utf8(bytes) {
        Ok(text) => text,
        Err(e) => {
            let (line, column) = line_column(bytes, e.valid_up_to());
            return Err(BvhError::InvalidUtf8 { line, column });
        }
    };
    Reader::new(text).read()
}

/// Reads the BVH file at `path` (see [`parse`]); errors name the file.
pub fn parse_file(path: &Path) -> Result<(Bvh, Vec<BvhWarning>), BvhError> {
    let bytes = std::fs::read(path).map_err(|error| BvhError::Io {
        path: path.to_path_buf(),
        error,
    })?;
    parse(&bytes).map_err(|error| BvhError::InFile {
        path: path.to_path_buf(),
        error: Box::new(error),
    })
}

/// 1-based line and byte column of byte `offset` in `bytes`.
fn line_column(bytes: &[u8], offset: usize) -> (usize, usize) {
    let before = &bytes[..offset.min(bytes.len())];
    let line = 1 + before.iter().filter(|&&b| b == b'\n').count();
    let line_start = before
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |p| p + 1);
    (line, before.len() - line_start + 1)
}

/// Separator bytes inside a line.
#[inline(always)]
fn is_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\r' | 0x0b | 0x0c)
}

/// A token quoted for an error message (escaped, cut to [`QUOTE_MAX`] characters).
fn quote(text: &str) -> String {
    let mut s = String::from("`");
    for (i, c) in text.chars().enumerate() {
        if i == QUOTE_MAX {
            s.push('…');
            break;
        }
        s.extend(c.escape_debug());
    }
    s.push('`');
    s
}

/// Case-insensitive keyword match.
fn kw(text: &str, keyword: &str) -> bool {
    text.eq_ignore_ascii_case(keyword)
}

/// The channel named `text` (any letter case).
fn channel_from_name(text: &str) -> Option<Channel> {
    ALL_CHANNELS.into_iter().find(|c| kw(text, c.name()))
}

/// One whitespace-separated token and where it starts.
#[derive(Clone, Copy, Debug)]
struct Token<'a> {
    text: &'a str,
    line: usize,
    column: usize,
}

/// Splits the header into tokens, counting lines.
#[derive(Clone)]
struct Lexer<'a> {
    text: &'a str,
    pos: usize,
    line: usize,
    line_start: usize,
}

impl<'a> Lexer<'a> {
    fn new(text: &'a str) -> Self {
        let pos = if text.starts_with('\u{feff}') { 3 } else { 0 };
        Lexer {
            text,
            pos,
            line: 1,
            line_start: pos,
        }
    }

    /// Skips separators (but not a line feed).
    fn skip_spaces(&mut self) {
        let b = self.text.as_bytes();
        while self.pos < b.len() && is_space(b[self.pos]) {
            self.pos += 1;
        }
    }

    /// The next token, crossing line ends; `None` at the end of the input.
    fn next(&mut self) -> Option<Token<'a>> {
        let b = self.text.as_bytes();
        loop {
            self.skip_spaces();
            if self.pos < b.len() && b[self.pos] == b'\n' {
                self.pos += 1;
                self.line += 1;
                self.line_start = self.pos;
            } else {
                break;
            }
        }
        if self.pos >= b.len() {
            return None;
        }
        let start = self.pos;
        while self.pos < b.len() && !is_space(b[self.pos]) && b[self.pos] != b'\n' {
            self.pos += 1;
        }
        Some(self.token(start))
    }

    /// The next token if it is on the current line.
    fn next_on_line(&mut self) -> Option<Token<'a>> {
        let line = self.line;
        let mut ahead = self.clone();
        let tok = ahead.next()?;
        if tok.line == line {
            *self = ahead;
            Some(tok)
        } else {
            None
        }
    }

    /// The rest of the current line with surrounding separators trimmed (possibly empty).
    fn rest_of_line(&mut self) -> Token<'a> {
        self.skip_spaces();
        let b = self.text.as_bytes();
        let start = self.pos;
        while self.pos < b.len() && b[self.pos] != b'\n' {
            self.pos += 1;
        }
        let mut end = self.pos;
        while end > start && is_space(b[end - 1]) {
            end -= 1;
        }
        Token {
            text: &self.text[start..end],
            line: self.line,
            column: start - self.line_start + 1,
        }
    }

    fn token(&self, start: usize) -> Token<'a> {
        Token {
            text: &self.text[start..self.pos],
            line: self.line,
            column: start - self.line_start + 1,
        }
    }
}

/// A joint whose `{` has been read and whose `}` has not.
#[derive(Clone, Copy)]
struct Open {
    joint: usize,
    opened: usize,
    has_offset: bool,
    has_channels: bool,
}

/// Parser state: the lexer over the header and what has been read so far.
struct Reader<'a> {
    lex: Lexer<'a>,
    joints: Vec<BvhJoint>,
    channel_count: usize,
    warnings: Vec<BvhWarning>,
    /// Line of each joint name read so far.
    names: std::collections::HashMap<String, usize>,
}

fn expected(tok: Token<'_>, what: impl Into<String>) -> BvhError {
    BvhError::Expected {
        line: tok.line,
        column: tok.column,
        expected: what.into(),
        found: quote(tok.text),
    }
}

impl<'a> Reader<'a> {
    fn new(text: &'a str) -> Self {
        Reader {
            lex: Lexer::new(text),
            joints: Vec::new(),
            channel_count: 0,
            warnings: Vec::new(),
            names: std::collections::HashMap::new(),
        }
    }

    fn read(mut self) -> Result<(Bvh, Vec<BvhWarning>), BvhError> {
        let Some(first) = self.lex.next() else {
            return Err(BvhError::Empty {
                line: self.lex.line,
            });
        };
        if !kw(first.text, "HIERARCHY") {
            return Err(expected(first, "HIERARCHY"));
        }
        self.hierarchy()?;
        let (frames, frames_line) = self.frames()?;
        let frame_time = self.frame_time()?;
        if frames > 0 && self.channel_count == 0 {
            return Err(BvhError::NoChannels {
                line: frames_line,
                frames,
            });
        }
        // The motion starts on the line after `Frame Time:`.
        let text = self.lex.text;
        let start = (self.lex.pos + 1).min(text.len());
        // Each channel's limit: degrees for rotations, file units for positions.
        let limits: Vec<f64> = self
            .joints
            .iter()
            .flat_map(|j| j.channels.iter())
            .map(|c| {
                if c.is_rotation() {
                    MAX_ANGLE_DEG
                } else {
                    MAX_LENGTH_UNITS
                }
            })
            .collect();
        let motion = read_motion(
            text,
            start,
            self.lex.line + 1,
            frames,
            frames_line,
            &limits,
            &mut self.warnings,
        )?;
        let bvh = Bvh {
            joints: self.joints,
            frame_time,
            channel_count: self.channel_count,
            motion,
        };
        Ok((bvh, self.warnings))
    }

    /// Reads everything from the first ROOT to MOTION (consumed).
    fn hierarchy(&mut self) -> Result<(), BvhError> {
        let mut stack: Vec<Open> = Vec::new();
        loop {
            let Some(tok) = self.lex.next() else {
                return Err(self.end_in_hierarchy(stack.last()));
            };
            match stack.last() {
                None => {
                    if self.outside_joints(tok, &mut stack)? {
                        return Ok(());
                    }
                }
                Some(&open) => self.joint_item_of(open, tok, &mut stack)?,
            }
        }
    }

    /// The error for a file that ends in the hierarchy: inside joint `open`, before any ROOT, or
    /// before MOTION.
    fn end_in_hierarchy(&self, open: Option<&Open>) -> BvhError {
        let line = self.lex.line;
        match open {
            Some(open) => BvhError::Unclosed {
                line,
                joint: self.joints[open.joint].name.clone(),
                opened: open.opened,
                found: "the end of the file".into(),
            },
            None if self.joints.is_empty() => BvhError::UnexpectedEnd {
                line,
                expected: "ROOT".into(),
            },
            None => BvhError::MissingMotion { line },
        }
    }

    /// A token outside every joint: ROOT opens one on `stack`, MOTION after a ROOT ends the
    /// hierarchy (true); anything else is an error.
    fn outside_joints(&mut self, tok: Token<'_>, stack: &mut Vec<Open>) -> Result<bool, BvhError> {
        let t = tok.text;
        if kw(t, "ROOT") {
            stack.push(self.begin_joint(None)?);
            Ok(false)
        } else if kw(t, "MOTION") && !self.joints.is_empty() {
            Ok(true)
        } else if t == "}" {
            Err(BvhError::UnmatchedClose {
                line: tok.line,
                column: tok.column,
            })
        } else if self.joints.is_empty() {
            Err(expected(tok, "ROOT"))
        } else {
            Err(expected(tok, "ROOT or MOTION"))
        }
    }

    /// A token inside joint `open` (the top of `stack`): its OFFSET or CHANNELS, a child JOINT
    /// or End Site, or the `}` that closes it.
    fn joint_item_of(
        &mut self,
        open: Open,
        tok: Token<'_>,
        stack: &mut Vec<Open>,
    ) -> Result<(), BvhError> {
        let t = tok.text;
        let j = open.joint;
        if kw(t, "OFFSET") {
            if open.has_offset {
                return Err(self.joint_item(j, tok, "has a second OFFSET"));
            }
            let what = format!("OFFSET of joint `{}`", self.joints[j].name);
            self.joints[j].offset = self.vec3(&what)?;
            if let Some(o) = stack.last_mut() {
                o.has_offset = true;
            }
        } else if kw(t, "CHANNELS") {
            if open.has_channels {
                return Err(self.joint_item(j, tok, "has a second CHANNELS line"));
            }
            let channels = self.channels(tok, j)?;
            self.joints[j].first_channel = self.channel_count;
            self.channel_count += channels.len();
            self.joints[j].channels = channels;
            if let Some(o) = stack.last_mut() {
                o.has_channels = true;
            }
        } else if kw(t, "JOINT") {
            self.require_items(open, tok)?;
            if stack.len() >= MAX_DEPTH {
                return Err(BvhError::TooLarge {
                    line: tok.line,
                    what: format!(
                        "the hierarchy is nested deeper than {MAX_DEPTH} joints (a human \
                         skeleton is about 10 deep)"
                    ),
                });
            }
            stack.push(self.begin_joint(Some(j))?);
        } else if kw(t, "End") {
            self.require_items(open, tok)?;
            self.end_site(tok, j)?;
        } else if t == "}" {
            self.require_items(open, tok)?;
            stack.pop();
        } else if kw(t, "MOTION") || kw(t, "ROOT") {
            return Err(BvhError::Unclosed {
                line: tok.line,
                joint: self.joints[j].name.clone(),
                opened: open.opened,
                found: quote(t),
            });
        } else {
            return Err(expected(tok, "OFFSET, CHANNELS, JOINT, End Site or `}`"));
        }
        Ok(())
    }

    fn joint_item(&self, j: usize, tok: Token<'_>, problem: &str) -> BvhError {
        BvhError::JointItem {
            line: tok.line,
            joint: self.joints[j].name.clone(),
            problem: problem.to_string(),
        }
    }

    /// Errors unless the open joint has had its OFFSET and CHANNELS before `tok`.
    fn require_items(&self, open: Open, tok: Token<'_>) -> Result<(), BvhError> {
        for (has, item) in [(open.has_offset, "OFFSET"), (open.has_channels, "CHANNELS")] {
            if !has {
                let problem = format!("has no {item}: expected {item} before {}", quote(tok.text));
                return Err(self.joint_item(open.joint, tok, &problem));
            }
        }
        Ok(())
    }

    /// After ROOT/JOINT: the name (rest of the line) and the opening brace.
    fn begin_joint(&mut self, parent: Option<usize>) -> Result<Open, BvhError> {
        let keyword = if parent.is_some() { "JOINT" } else { "ROOT" };
        let name = self.lex.rest_of_line();
        if name.text.is_empty() {
            return Err(BvhError::Expected {
                line: name.line,
                column: name.column,
                expected: format!("a joint name after {keyword}"),
                found: "the end of the line".into(),
            });
        }
        if self.joints.len() >= MAX_JOINTS {
            return Err(BvhError::TooLarge {
                line: name.line,
                what: format!("the hierarchy has more than {MAX_JOINTS} joints"),
            });
        }
        if let Some(&first_line) = self.names.get(name.text) {
            return Err(BvhError::DuplicateJoint {
                line: name.line,
                name: quote(name.text),
                first_line,
            });
        }
        self.names.insert(name.text.to_string(), name.line);
        let brace = self.next_or_end(|| format!("`{{` opening joint {}", quote(name.text)))?;
        if brace.text != "{" {
            return Err(expected(
                brace,
                format!("`{{` opening joint {}", quote(name.text)),
            ));
        }
        self.joints.push(BvhJoint {
            name: name.text.to_string(),
            parent,
            offset: DVec3::ZERO,
            channels: Vec::new(),
            first_channel: 0,
            end_site: None,
        });
        Ok(Open {
            joint: self.joints.len() - 1,
            opened: brace.line,
            has_offset: false,
            has_channels: false,
        })
    }

    /// After `End`: `Site { OFFSET x y z }`.
    fn end_site(&mut self, end: Token<'_>, j: usize) -> Result<(), BvhError> {
        let name = &self.joints[j].name;
        let ctx = format!("End Site of joint `{name}`");
        let site = self.next_or_end(|| "`Site` after `End`".into())?;
        if !kw(site.text, "Site") {
            return Err(expected(site, "`Site` after `End`"));
        }
        if self.joints[j].end_site.is_some() {
            return Err(self.joint_item(j, end, "has a second End Site"));
        }
        for want in ["{", "OFFSET"] {
            let tok = self.next_or_end(|| format!("`{want}` of the {ctx}"))?;
            if !kw(tok.text, want) {
                return Err(expected(tok, format!("`{want}` of the {ctx}")));
            }
        }
        let offset = self.vec3(&format!("OFFSET of the {ctx}"))?;
        let close = self.next_or_end(|| format!("`}}` closing the {ctx}"))?;
        if close.text != "}" {
            return Err(expected(close, format!("`}}` closing the {ctx}")));
        }
        self.joints[j].end_site = Some(offset);
        Ok(())
    }

    /// The next token, or an error saying the file ends where `what` was expected.
    fn next_or_end(&mut self, what: impl FnOnce() -> String) -> Result<Token<'a>, BvhError> {
        self.lex.next().ok_or_else(|| BvhError::UnexpectedEnd {
            line: self.lex.line,
            expected: what(),
        })
    }

    /// Three finite numbers (after OFFSET).
    fn vec3(&mut self, what: &str) -> Result<DVec3, BvhError> {
        let mut v = [0.0; 3];
        for (i, axis) in ["x", "y", "z"].into_iter().enumerate() {
            let desc = || format!("a number ({axis} of the {what})");
            let tok = self.next_or_end(desc)?;
            let x: f64 = tok.text.parse().map_err(|_| expected(tok, desc()))?;
            if !x.is_finite() {
                return Err(BvhError::NonFinite {
                    line: tok.line,
                    column: tok.column,
                    what: format!("{axis} of the {what}"),
                    found: tok.text.chars().take(QUOTE_MAX).collect(),
                });
            }
            if x.abs() > MAX_LENGTH_UNITS {
                return Err(BvhError::OutOfRange {
                    line: tok.line,
                    column: tok.column,
                    what: format!("{axis} of the {what}"),
                    found: tok.text.chars().take(QUOTE_MAX).collect(),
                    limit: MAX_LENGTH_UNITS,
                });
            }
            v[i] = x;
        }
        Ok(DVec3::from_array(v))
    }

    /// After CHANNELS: the count and that many channel names, all on the CHANNELS line.
    fn channels(&mut self, at: Token<'_>, j: usize) -> Result<Vec<Channel>, BvhError> {
        let name = &self.joints[j].name;
        let count_desc = format!("the channel count of joint `{name}` after CHANNELS");
        let Some(count_tok) = self.lex.next_on_line() else {
            return Err(self.end_of_line(at, count_desc));
        };
        let n: usize = count_tok
            .text
            .parse()
            .map_err(|_| expected(count_tok, count_desc))?;
        let mut channels = Vec::new();
        for i in 0..n {
            let Some(tok) = self.lex.next_on_line() else {
                let what = format!(
                    "{n} channel names for joint `{name}` ({i} given on the CHANNELS line)"
                );
                return Err(self.end_of_line(at, what));
            };
            let Some(c) = channel_from_name(tok.text) else {
                return Err(BvhError::UnknownChannel {
                    line: tok.line,
                    column: tok.column,
                    found: tok.text.chars().take(QUOTE_MAX).collect(),
                });
            };
            channels.push(c);
        }
        if let Some(extra) = self.lex.next_on_line() {
            return Err(expected(
                extra,
                format!("the end of the line after the {n} channels of joint `{name}`"),
            ));
        }
        Ok(channels)
    }

    /// "expected `what`, found the end of the line" at the end of `at`'s line.
    fn end_of_line(&self, at: Token<'_>, what: String) -> BvhError {
        let mut probe = self.lex.clone();
        let rest = probe.rest_of_line();
        BvhError::Expected {
            line: at.line,
            column: rest.column + rest.text.len(),
            expected: what,
            found: "the end of the line".into(),
        }
    }

    /// `Frames: N` (also `Frames:N`); returns N and its line.
    fn frames(&mut self) -> Result<(usize, usize), BvhError> {
        let tok = self.next_or_end(|| "`Frames:` after MOTION".into())?;
        let prefix = tok.text.get(..7);
        if !prefix.is_some_and(|p| kw(p, "Frames:")) {
            return Err(expected(tok, "`Frames:` after MOTION"));
        }
        let num = if tok.text.len() > 7 {
            Token {
                text: &tok.text[7..],
                line: tok.line,
                column: tok.column + 7,
            }
        } else {
            self.lex
                .next_on_line()
                .ok_or_else(|| self.end_of_line(tok, "the frame count after `Frames:`".into()))?
        };
        let n: usize = num
            .text
            .parse()
            .map_err(|_| expected(num, "a whole number of frames after `Frames:`"))?;
        Ok((n, tok.line))
    }

    /// `Frame Time: t` (also `Frame Time:t`); requires 0 < t < ∞ and nothing else on the line.
    fn frame_time(&mut self) -> Result<f64, BvhError> {
        let tok = self.next_or_end(|| "`Frame Time:` after `Frames:`".into())?;
        if !kw(tok.text, "Frame") {
            return Err(expected(tok, "`Frame Time:` after `Frames:`"));
        }
        let time = self
            .lex
            .next_on_line()
            .ok_or_else(|| self.end_of_line(tok, "`Time:` after `Frame`".into()))?;
        if !time.text.get(..5).is_some_and(|p| kw(p, "Time:")) {
            return Err(expected(time, "`Time:` after `Frame`"));
        }
        let num = if time.text.len() > 5 {
            Token {
                text: &time.text[5..],
                line: time.line,
                column: time.column + 5,
            }
        } else {
            self.lex.next_on_line().ok_or_else(|| {
                self.end_of_line(tok, "seconds per frame after `Frame Time:`".into())
            })?
        };
        let t: f64 = num
            .text
            .parse()
            .map_err(|_| expected(num, "a number of seconds after `Frame Time:`"))?;
        if !(t.is_finite() && t > 0.0) {
            return Err(BvhError::FrameTime {
                line: num.line,
                found: num.text.chars().take(QUOTE_MAX).collect(),
            });
        }
        let rest = self.lex.rest_of_line();
        if !rest.text.is_empty() {
            return Err(BvhError::Expected {
                line: rest.line,
                column: rest.column,
                expected:
                    "the end of the line after `Frame Time:` (motion starts on the next line)"
                        .into(),
                found: quote(rest.text),
            });
        }
        Ok(t)
    }
}

/// Reads `frames` lines of `limits.len()` values each, starting at byte `pos` (line `line`);
/// value `c` of a frame may not exceed `limits[c]` in magnitude.
///
/// The hot loop: for each value find its bytes, `parse::<f64>` them and push into the
/// pre-sized vector. Blank lines are skipped with a warning; lines after the last declared
/// frame are ignored with a warning.
fn read_motion(
    text: &str,
    mut pos: usize,
    mut line: usize,
    frames: usize,
    frames_line: usize,
    limits: &[f64],
    warnings: &mut Vec<BvhWarning>,
) -> Result<Vec<f64>, BvhError> {
    let channels = limits.len();
    let bytes = text.as_bytes();
    let n = bytes.len();
    // Every value needs at least two bytes, so the rest of the file bounds the allocation
    // however large `Frames:` claims to be.
    let capacity = frames
        .saturating_mul(channels)
        .min((n - pos) / 2 + channels);
    let mut motion: Vec<f64> = Vec::with_capacity(capacity);
    let mut frame = 0;
    let mut blank_lines = 0usize;
    let mut first_blank = 0usize;
    while frame < frames {
        if pos >= n {
            return Err(BvhError::MissingFrames {
                line,
                found: frame,
                declared: frames,
                declared_line: frames_line,
            });
        }
        let count = frame_values(text, &mut pos, line, frame, limits, &mut motion)?;
        if count == 0 {
            if blank_lines == 0 {
                first_blank = line;
            }
            blank_lines += 1;
        } else if count < channels {
            return Err(BvhError::FrameValueCount {
                line,
                frame: frame + 1,
                expected: channels,
                found: count,
            });
        } else {
            frame += 1;
        }
        pos += 1; // past the line feed (or past the end, which ends the loop)
        line += 1;
    }
    if blank_lines > 0 {
        warnings.push(BvhWarning {
            line: first_blank,
            message: format!("{blank_lines} blank line(s) inside the motion ignored"),
        });
    }
    let tail = bytes.get(pos..).unwrap_or(&[]);
    warnings.extend(lines_after_frames(tail, line, frames, frames_line));
    Ok(motion)
}

/// Reads the values of the motion line of frame `frame` (from 0) starting at byte `*pos` (line
/// `line`) into `motion`, leaving `*pos` on its line feed (or the end); returns how many there
/// are. Errors: more than `limits.len()`, or a value that is not a number within its limit.
fn frame_values(
    text: &str,
    pos: &mut usize,
    line: usize,
    frame: usize,
    limits: &[f64],
    motion: &mut Vec<f64>,
) -> Result<usize, BvhError> {
    let (bytes, n, channels) = (text.as_bytes(), text.len(), limits.len());
    let line_start = *pos;
    let mut count = 0usize;
    loop {
        while *pos < n && is_space(bytes[*pos]) {
            *pos += 1;
        }
        if *pos >= n || bytes[*pos] == b'\n' {
            break;
        }
        let start = *pos;
        while *pos < n && !is_space(bytes[*pos]) && bytes[*pos] != b'\n' {
            *pos += 1;
        }
        count += 1;
        if count > channels {
            return Err(BvhError::FrameValueCount {
                line,
                frame: frame + 1,
                expected: channels,
                found: count + count_tokens(&bytes[*pos..]),
            });
        }
        let token = &text[start..*pos];
        let at = (line, start - line_start + 1);
        motion.push(motion_value(token, limits[count - 1], at, count, frame)?);
    }
    Ok(count)
}

/// Value `count` (from 1) of frame `frame` (from 0), the text `token` at (line, column) `at`:
/// a finite number no larger than `limit` in magnitude.
fn motion_value(
    token: &str,
    limit: f64,
    (line, column): (usize, usize),
    count: usize,
    frame: usize,
) -> Result<f64, BvhError> {
    let Ok(v) = token.parse::<f64>() else {
        return Err(BvhError::Expected {
            line,
            column,
            expected: format!("a number (value {count} of frame {})", frame + 1),
            found: quote(token),
        });
    };
    if !v.is_finite() {
        return Err(BvhError::NonFinite {
            line,
            column,
            what: format!("value {count} of frame {}", frame + 1),
            found: token.chars().take(QUOTE_MAX).collect(),
        });
    }
    if v.abs() > limit {
        let kind = if limit == MAX_ANGLE_DEG {
            "a rotation in degrees"
        } else {
            "a position in file units"
        };
        return Err(BvhError::OutOfRange {
            line,
            column,
            what: format!("value {count} of frame {}, {kind},", frame + 1),
            found: token.chars().take(QUOTE_MAX).collect(),
            limit,
        });
    }
    Ok(v)
}

/// The warning for the non-blank lines of `tail` (starting at line `line`) after the `frames`
/// frames declared on line `frames_line`, which are ignored; `None` when there are none.
fn lines_after_frames(
    tail: &[u8],
    line: usize,
    frames: usize,
    frames_line: usize,
) -> Option<BvhWarning> {
    let mut extra = 0usize;
    let mut first_extra = 0usize;
    for (i, l) in tail.split(|&b| b == b'\n').enumerate() {
        if l.iter().any(|&b| !is_space(b)) {
            if extra == 0 {
                first_extra = line + i;
            }
            extra += 1;
        }
    }
    (extra > 0).then(|| BvhWarning {
        line: first_extra,
        message: format!(
            "{extra} line(s) after the {frames} frames declared on line {frames_line} ignored"
        ),
    })
}

/// Number of tokens on the rest of the current line of `bytes`.
fn count_tokens(bytes: &[u8]) -> usize {
    let end = bytes
        .iter()
        .position(|&b| b == b'\n')
        .unwrap_or(bytes.len());
    bytes[..end]
        .split(|&b| is_space(b))
        .filter(|t| !t.is_empty())
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;

    const SMALL: &str = "HIERARCHY\nROOT Hips\n{\n\tOFFSET 0 0 0\n\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation\n\tJOINT Spine\n\t{\n\t\tOFFSET 0 1 0\n\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n\t\tEnd Site\n\t\t{\n\t\t\tOFFSET 0 .5 0\n\t\t}\n\t}\n}\nMOTION\nFrames: 2\nFrame Time: .0083333\n1 2 3 4 5 6 7 8 9\n-0 1e-06 .5 0 0 0 0 0 -1.5\n";

    #[test]
    fn reads_a_small_file() {
        let (bvh, warnings) = parse(SMALL.as_bytes()).unwrap();
        assert!(warnings.is_empty());
        assert_eq!(bvh.joints.len(), 2);
        assert_eq!(bvh.joints[1].parent, Some(0));
        assert_eq!(bvh.joints[1].first_channel, 6);
        assert_eq!(bvh.joints[1].end_site, Some(DVec3::new(0.0, 0.5, 0.0)));
        assert_eq!(bvh.channel_count, 9);
        assert_eq!(bvh.frame_time, 0.0083333);
        assert_eq!(bvh.frame(1)[1], 1e-6);
        assert!(bvh.frame(1)[0].is_sign_negative());
    }

    #[test]
    fn line_column_counts_from_one() {
        assert_eq!(line_column(b"ab\ncd", 4), (2, 2));
        assert_eq!(line_column(b"ab", 0), (1, 1));
    }

    #[test]
    fn quote_cuts_long_tokens() {
        let long = "x".repeat(100);
        let q = quote(&long);
        assert_eq!(q.chars().count(), QUOTE_MAX + 3);
        assert!(q.ends_with("…`"));
    }

    #[test]
    fn count_tokens_stops_at_line_end() {
        assert_eq!(count_tokens(b" 1 2\t3\r\n4 5"), 3);
    }
}
