//! The text forms of numbers that flags and files share: a point `X,Y,Z`, a grid `COLSxROWS`,
//! an image size `WIDTHxHEIGHT`, a mark `NAME=X,Y,Z`, a heading in degrees, an interval
//! `MIN,MAX`. Each returns the value or one sentence saying what was expected.

/// Text not in the form asked for: one sentence saying what was expected and what came.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct ParseError(pub String);

impl From<String> for ParseError {
    fn from(s: String) -> Self {
        Self(s)
    }
}

/// Comma-separated finite numbers, as many as one of `n`; `what` says what was expected.
pub(crate) fn numbers(s: &str, n: &[usize], what: &str) -> Result<Vec<f64>, ParseError> {
    let v: Result<Vec<f64>, _> = s.split(',').map(|x| x.trim().parse::<f64>()).collect();
    match v {
        Ok(v) if n.contains(&v.len()) && v.iter().all(|x| x.is_finite()) => Ok(v),
        _ => Err(format!("expected {what}, got '{s}'").into()),
    }
}

/// A point X,Y,Z (m).
pub fn parse_point(s: &str) -> Result<[f64; 3], ParseError> {
    let v = numbers(s, &[3], "X,Y,Z (three numbers in metres)")?;
    Ok([v[0], v[1], v[2]])
}

/// A heading in degrees, any finite number, as 0…360° (400 is 40°).
pub fn parse_facing(s: &str) -> Result<f64, ParseError> {
    match s.trim().parse::<f64>() {
        Ok(d) if d.is_finite() => Ok(d.rem_euclid(360.0)),
        _ => Err(format!(
            "expected a heading in degrees from +x towards +y (0 = +x, 90 = +y), got '{s}'"
        )
        .into()),
    }
}

/// The sun ALT,AZ in degrees: its altitude, and its azimuth in the room's frame as a heading
/// (from +x towards +y; any finite number, as 0…360°).
pub fn parse_sun(s: &str) -> Result<[f64; 2], ParseError> {
    let v = numbers(
        s,
        &[2],
        "ALT,AZ: the sun's altitude and its azimuth from +x towards +y, in degrees",
    )?;
    // The azimuth as [sun] azimuth_deg takes it: one turn either way, read as 0…360.
    if !(-360.0..=360.0).contains(&v[1]) {
        return Err(format!("the azimuth in '{s}' is outside -360…360°").into());
    }
    Ok([v[0], v[1].rem_euclid(360.0) + 0.0])
}

/// "AxB" (also "A×B") as two numbers; `bad` says what was expected.
pub(crate) fn parse_pair(
    s: &str,
    bad: &dyn Fn() -> ParseError,
) -> Result<(usize, usize), ParseError> {
    let (a, b) = s.split_once(['x', 'X', '×']).ok_or_else(bad)?;
    Ok((
        a.trim().parse::<usize>().map_err(|_| bad())?,
        b.trim().parse::<usize>().map_err(|_| bad())?,
    ))
}

/// An image size WIDTHxHEIGHT, 1…16384 pixels a side.
pub(crate) fn parse_image_size(s: &str) -> Result<(u32, u32), ParseError> {
    let (w, h) = parse_pair(s, &|| {
        format!("expected WIDTHxHEIGHT such as 160x120, got '{s}'").into()
    })?;
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err(format!("an image of {w}×{h} pixels is outside 1…16384 a side").into());
    }
    Ok((w as u32, h as u32))
}

/// A grid COLSxROWS, 1 to 1,000,000 nodes.
pub fn parse_grid(s: &str) -> Result<(usize, usize), ParseError> {
    let (a, b) = parse_pair(s, &|| {
        format!("expected COLSxROWS such as 20x20, got '{s}'").into()
    })?;
    if a == 0 || b == 0 || a * b > 1_000_000 {
        return Err(
            format!("a grid of {a}×{b} nodes is not allowed (1 to 1,000,000 nodes)").into(),
        );
    }
    Ok((a, b))
}

/// A named point NAME=U,V or NAME=X,Y,Z.
pub fn parse_mark(s: &str) -> Result<(String, Vec<f64>), ParseError> {
    let (name, rest) = s
        .split_once('=')
        .ok_or_else(|| ParseError(format!("expected NAME=U,V or NAME=X,Y,Z, got '{s}'")))?;
    if name.trim().is_empty() {
        return Err(format!("the mark '{s}' has no name").into());
    }
    Ok((
        name.trim().to_string(),
        numbers(rest, &[2, 3], "U,V or X,Y,Z after the name")?,
    ))
}

/// An interval MIN,MAX of seconds, 0 ≤ MIN ≤ MAX.
pub(crate) fn parse_interval(s: &str) -> Result<[f64; 2], ParseError> {
    let v = numbers(s, &[2], "MIN,MAX (two numbers in seconds)")?;
    if !(v[0] >= 0.0 && v[1] >= v[0]) {
        return Err(format!("expected 0 <= MIN <= MAX, got '{s}'").into());
    }
    Ok([v[0], v[1]])
}

/// A switch: on or off.
pub(crate) fn parse_on_off(s: &str) -> Result<bool, ParseError> {
    match s.trim() {
        "on" => Ok(true),
        "off" => Ok(false),
        _ => Err(ParseError(format!("expected on or off, got '{s}'"))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parsers_accept_and_refuse() {
        assert_eq!(parse_grid("20x20"), Ok((20, 20)));
        assert_eq!(parse_grid("3×4"), Ok((3, 4)));
        assert!(parse_grid("0x5").is_err());
        assert!(parse_grid("20").is_err());
        assert_eq!(parse_point("1, 2,3.5"), Ok([1.0, 2.0, 3.5]));
        assert!(parse_point("1,2").is_err());
        assert!(parse_point("1,2,nan").is_err());
        assert_eq!(parse_mark("A=1,2"), Ok(("A".into(), vec![1.0, 2.0])));
        assert!(parse_mark("=1,2").is_err());
        assert!(parse_mark("A=1").is_err());
        // Issue 41: NaN blamed missing walls; 400 was echoed as 400°.
        assert_eq!(parse_facing("400"), Ok(40.0));
        assert_eq!(parse_facing("-90"), Ok(270.0));
        let nan = parse_facing("NaN").unwrap_err().0;
        assert!(nan.contains("degrees") && nan.contains("NaN"), "{nan}");
        assert!(parse_facing("inf").is_err());
        assert_eq!(parse_on_off("off"), Ok(false));
        assert!(parse_on_off("yes").is_err());
    }
}
