//! BC7 blocks whose colour is one colour, stored exactly.
//!
//! A 4x4 block of one RGB colour is common in painted maps (a flat base colour, a filled
//! stroke), and BC7 encoders often miss it by a level: mode 6 gives each endpoint one p-bit
//! shared by its channels, so a colour whose channels differ in parity, such as the typical
//! project's background `(255, 238, 230)`, decodes one level off in a channel, at every effort
//! of ISPC's encoder. Mode 5 has 7-bit colour endpoints without p-bits, 8-bit alpha endpoints
//! and alpha indices of its own: each 8-bit value is the interpolation, at the weight of
//! index 1 (21/64), of some pair of 7-bit endpoints (checked for all 256 in the tests). So
//! with every colour index 1, the colour is exact whatever the alpha does, and the alpha is
//! fitted between its own smallest and largest value.
//!
//! [`refine`] runs after any BC7 encoder (ISPC's, the portable one, a GPU's): in each block of
//! one colour it takes this mode 5 block where it decodes closer to the texels (summed
//! squared error over the components the file stores) than the encoder's block.

use std::sync::LazyLock;

use block_compression::decode::decode_block_bc7;

/// BC7's 2-bit interpolation weights, out of 64.
const WEIGHTS: [u32; 4] = [0, 21, 43, 64];

/// A mode 5 colour endpoint (7 bits) as the decoder widens it to 8.
fn widen7(v: u8) -> u32 {
    u32::from(v) << 1 | u32::from(v) >> 6
}

/// BC7's interpolation of two 8-bit endpoints at `weight` (out of 64).
fn mix(a: u32, b: u32, weight: u32) -> u32 {
    ((64 - weight) * a + weight * b + 32) >> 6
}

/// For each 8-bit value, a pair of 7-bit endpoints whose mix at index 1 decodes to it (the
/// nearest pair).
static PAIRS: LazyLock<[(u8, u8); 256]> = LazyLock::new(|| {
    let mut pairs = [(0, 0); 256];
    let mut gap = [u8::MAX; 256];
    for a in 0..128_u8 {
        for b in 0..128_u8 {
            let value = mix(widen7(a), widen7(b), WEIGHTS[1]) as usize;
            let apart = a.abs_diff(b);
            if apart < gap[value] {
                gap[value] = apart;
                pairs[value] = (a, b);
            }
        }
    }
    pairs
});

/// Writes `bits` into a 128-bit block, least significant first.
struct Bits {
    block: u128,
    at: u32,
}

impl Bits {
    fn put(&mut self, value: u32, count: u32) {
        self.block |= u128::from(value) << self.at;
        self.at += count;
    }
}

/// The mode 5 block for 16 texels (RGBA, row by row) of one RGB colour, and the alpha it
/// decodes to at each texel.
fn mode5(texels: &[[u8; 4]; 16]) -> ([u8; 16], [u8; 16]) {
    let [r, g, b, _] = texels[0];
    let low = texels.iter().map(|t| t[3]).min().unwrap_or(0);
    let high = texels.iter().map(|t| t[3]).max().unwrap_or(0);
    let levels = WEIGHTS.map(|w| mix(u32::from(low), u32::from(high), w));
    let mut index = texels.map(|t| {
        let a = u32::from(t[3]);
        (0..4).min_by_key(|&i| levels[i].abs_diff(a)).unwrap_or(0)
    });
    let (mut a0, mut a1) = (low, high);
    // The first texel's index is stored in one bit: it must be 0 or 1.
    if index[0] >= 2 {
        (a0, a1) = (high, low);
        index = index.map(|i| 3 - i);
    }
    let mut bits = Bits { block: 0, at: 0 };
    bits.put(1 << 5, 6); // mode 5
    bits.put(0, 2); // no rotation
    for channel in [r, g, b] {
        let (e0, e1) = PAIRS[usize::from(channel)];
        bits.put(u32::from(e0), 7);
        bits.put(u32::from(e1), 7);
    }
    bits.put(u32::from(a0), 8);
    bits.put(u32::from(a1), 8);
    // Colour indices: all 1 (the first in one bit).
    bits.put(1, 1);
    for _ in 1..16 {
        bits.put(1, 2);
    }
    bits.put(index[0] as u32, 1);
    for i in &index[1..] {
        bits.put(*i as u32, 2);
    }
    debug_assert_eq!(bits.at, 128);
    let alpha = index.map(|i| mix(u32::from(a0), u32::from(a1), WEIGHTS[i]) as u8);
    (bits.block.to_le_bytes(), alpha)
}

/// Summed squared error of `decoded` against `texels`, over the first `channels` components.
fn error(texels: &[[u8; 4]; 16], decoded: &[u8], channels: usize) -> u32 {
    texels
        .iter()
        .zip(decoded.chunks_exact(4))
        .flat_map(|(t, d)| (0..channels).map(move |c| u32::from(t[c].abs_diff(d[c])).pow(2)))
        .sum()
}

/// Replaces, in BC7 `blocks` (`width` texels across, as many rows as they cover), each
/// block of one RGB colour in `texels` (RGBA8, `width` across) with its exact mode 5 block
/// where that decodes closer over the components the file stores (alpha where `alpha`).
pub(super) fn refine(alpha: bool, blocks: &mut [u8], texels: &[u8], width: usize) {
    let channels = if alpha { 4 } else { 3 };
    let across = width / 4;
    for (n, block) in blocks.chunks_exact_mut(16).enumerate() {
        let (bx, by) = (n % across, n / across);
        let mut own = [[0_u8; 4]; 16];
        for (i, t) in own.iter_mut().enumerate() {
            let at = ((by * 4 + i / 4) * width + bx * 4 + i % 4) * 4;
            t.copy_from_slice(&texels[at..at + 4]);
        }
        if own.iter().any(|t| t[..3] != own[0][..3]) {
            continue;
        }
        let mut decoded = [0_u8; 64];
        decode_block_bc7(block, &mut decoded, 16);
        let before = error(&own, &decoded, channels);
        if before == 0 {
            continue;
        }
        let (exact, alpha) = mode5(&own);
        let after: u32 = if channels == 4 {
            own.iter()
                .zip(alpha)
                .map(|(t, a)| u32::from(t[3].abs_diff(a)).pow(2))
                .sum()
        } else {
            0
        };
        if after < before {
            block.copy_from_slice(&exact);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_value_has_a_pair_at_index_one() {
        for (value, (a, b)) in PAIRS.iter().enumerate() {
            assert_eq!(
                mix(widen7(*a), widen7(*b), WEIGHTS[1]) as usize,
                value,
                "{a} {b}"
            );
        }
    }

    fn decode(block: &[u8; 16]) -> [u8; 64] {
        let mut out = [0; 64];
        decode_block_bc7(block, &mut out, 16);
        out
    }

    #[test]
    fn a_solid_block_decodes_exactly_in_every_channel() {
        for colour in [
            [255, 238, 230, 255],
            [0, 1, 2, 3],
            [128, 127, 129, 0],
            [7, 200, 99, 254],
        ] {
            let (block, alpha) = mode5(&[colour; 16]);
            let decoded = decode(&block);
            for texel in decoded.chunks_exact(4) {
                assert_eq!(texel, colour);
            }
            assert_eq!(alpha, [colour[3]; 16]);
        }
    }

    #[test]
    fn alpha_beside_one_colour_decodes_as_said() {
        let mut texels = [[40, 90, 200, 0]; 16];
        for (i, t) in texels.iter_mut().enumerate() {
            // The first texel high, so the endpoints swap.
            t[3] = 250 - (i as u8) * 15;
        }
        let (block, alpha) = mode5(&texels);
        let decoded = decode(&block);
        for ((t, d), a) in texels.iter().zip(decoded.chunks_exact(4)).zip(alpha) {
            assert_eq!(d[..3], t[..3]);
            assert_eq!(d[3], a);
            assert!(t[3].abs_diff(a) <= 40, "{t:?} {a}");
        }
    }
}
