//! RVL, the lossless depth codec of Wilson (2017) that RTAB-Map uses for depth since 0.21.9:
//! runs of zeros and non-zeros, each value the zig-zag delta from the previous non-zero, in
//! variable-length nibbles packed into little-endian 32-bit words. RTAB-Map prefixes the stream
//! with `DEPTHRVL`, then the width and height as u32.

use mrtmap_io::bytes::Corrupt;

/// RTAB-Map's magic.
pub const MAGIC: &[u8] = b"DEPTHRVL";

struct Nibbles<'a> {
    data: &'a [u8],
    pos: usize,
    word: u32,
    left: u32,
    base: u64,
}

impl Nibbles<'_> {
    fn next_word(&mut self) -> Result<(), Corrupt> {
        let Some(b) = self.data.get(self.pos..self.pos + 4) else {
            return Err(Corrupt::new(
                self.base + self.pos as u64,
                "RVL stream ends before the image is complete",
            ));
        };
        self.word = u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
        self.pos += 4;
        self.left = 8;
        Ok(())
    }

    fn vle(&mut self) -> Result<u32, Corrupt> {
        let mut value: u64 = 0;
        let mut shift = 0;
        loop {
            if self.left == 0 {
                self.next_word()?;
            }
            let nibble = self.word >> 28;
            self.word <<= 4;
            self.left -= 1;
            value |= ((nibble & 7) as u64) << shift;
            shift += 3;
            if nibble & 8 == 0 {
                break;
            }
            if shift > 33 {
                return Err(Corrupt::new(
                    self.base + self.pos as u64,
                    "RVL value longer than 32 bits",
                ));
            }
        }
        u32::try_from(value)
            .map_err(|_| Corrupt::new(self.base + self.pos as u64, "RVL value longer than 32 bits"))
    }
}

/// Decodes `n` pixels of an RVL stream (`base`: its file offset, for errors).
pub fn decode(data: &[u8], n: usize, base: u64) -> Result<Vec<u16>, Corrupt> {
    let mut r = Nibbles {
        data,
        pos: 0,
        word: 0,
        left: 0,
        base,
    };
    let mut out = Vec::with_capacity(n);
    let mut previous: i32 = 0;
    let too_many = |r: &Nibbles<'_>| {
        Corrupt::new(
            r.base + r.pos as u64,
            format!("RVL runs add up to more than the image's {n} pixels"),
        )
    };
    while out.len() < n {
        let zeros = r.vle()? as usize;
        if zeros > n - out.len() {
            return Err(too_many(&r));
        }
        out.resize(out.len() + zeros, 0);
        let nonzeros = r.vle()? as usize;
        if nonzeros > n - out.len() {
            return Err(too_many(&r));
        }
        for _ in 0..nonzeros {
            let positive = r.vle()? as i64;
            let delta = ((positive >> 1) ^ -(positive & 1)) as i32;
            let current = previous.wrapping_add(delta) as u16;
            out.push(current);
            previous = current as i32;
        }
    }
    Ok(out)
}

/// Encodes pixels as an RVL stream.
pub fn encode(pixels: &[u16]) -> Vec<u8> {
    let mut out = Vec::with_capacity(pixels.len());
    let mut word: u32 = 0;
    let mut written = 0;
    let mut vle = |mut v: u32, out: &mut Vec<u8>| loop {
        let mut nibble = v & 7;
        v >>= 3;
        if v != 0 {
            nibble |= 8;
        }
        word = (word << 4) | nibble;
        written += 1;
        if written == 8 {
            out.extend_from_slice(&word.to_le_bytes());
            written = 0;
            word = 0;
        }
        if v == 0 {
            break;
        }
    };
    let mut i = 0;
    let mut previous: i32 = 0;
    while i < pixels.len() {
        let z0 = i;
        while i < pixels.len() && pixels[i] == 0 {
            i += 1;
        }
        vle((i - z0) as u32, &mut out);
        let n0 = i;
        while i < pixels.len() && pixels[i] != 0 {
            i += 1;
        }
        vle((i - n0) as u32, &mut out);
        for &p in &pixels[n0..i] {
            let delta = p as i32 - previous;
            vle(((delta << 1) ^ (delta >> 31)) as u32, &mut out);
            previous = p as i32;
        }
    }
    if written > 0 {
        out.extend_from_slice(&(word << (4 * (8 - written))).to_le_bytes());
    }
    out
}

/// RTAB-Map's depth blob: magic, width, height, RVL stream.
pub fn encode_rtabmap(width: u32, height: u32, pixels: &[u16]) -> Vec<u8> {
    let mut b = MAGIC.to_vec();
    b.extend_from_slice(&width.to_le_bytes());
    b.extend_from_slice(&height.to_le_bytes());
    b.extend_from_slice(&encode(pixels));
    b
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn known_runs_round_trip() {
        let px = [0u16, 0, 0, 1000, 1001, 999, 0, 65535, 1, 0];
        let e = encode(&px);
        assert_eq!(decode(&e, px.len(), 0).unwrap(), px);
        // Ask for more pixels than encoded: the stream runs out, an error not a panic.
        assert!(decode(&e, px.len() + 50, 0).is_err());
        assert!(decode(&[0xff; 3], 4, 0).is_err());
        // All-ones nibbles never end a value.
        assert!(decode(&[0xff; 64], 4, 0).is_err());
    }

    proptest! {
        #[test]
        fn any_depth_image_round_trips(px in proptest::collection::vec(prop_oneof![Just(0u16), any::<u16>(), 400u16..5000], 0..2000)) {
            let e = encode(&px);
            prop_assert_eq!(decode(&e, px.len(), 0).unwrap(), px);
        }
    }
}
