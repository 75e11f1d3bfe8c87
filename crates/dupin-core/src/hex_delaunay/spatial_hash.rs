//! A locality-preserving hasher for lattice coordinates.
//!
//! The refinement and the dual extraction visit hexagons in spatially coherent order (points are
//! queued in Morton order, the dual recursion is depth-first). A scrambling hash (SipHash, Fx)
//! scatters neighbouring hexagons over the whole table, so every look-up of a large table is a
//! cache miss and the cost per triangle grows with the table. This hasher interleaves the
//! coordinates' low bits (a Morton code) so neighbours land in nearby buckets, and takes the top
//! seven bits, which hashbrown uses as its tag byte, from a multiplicative mix so tags stay
//! distinct. Written by hand: no maintained crate offers a Morton-code `Hasher`.

use std::hash::{BuildHasher, Hasher};

/// Builds [`MortonHasher`]s.
#[derive(Debug, Clone, Copy, Default)]
pub struct MortonBuild;

impl BuildHasher for MortonBuild {
    type Hasher = MortonHasher;
    #[inline]
    fn build_hasher(&self) -> MortonHasher {
        MortonHasher {
            words: [0; 2],
            n: 0,
        }
    }
}

/// Hashes a pair of integers (the first two integer writes) by bit interleaving.
#[derive(Debug, Clone, Copy)]
pub struct MortonHasher {
    words: [u64; 2],
    n: usize,
}

#[inline]
fn spread(x: u64) -> u64 {
    // Spreads the low 32 bits of x to the even bit positions.
    let mut x = x & 0xFFFF_FFFF;
    x = (x | (x << 16)) & 0x0000_FFFF_0000_FFFF;
    x = (x | (x << 8)) & 0x00FF_00FF_00FF_00FF;
    x = (x | (x << 4)) & 0x0F0F_0F0F_0F0F_0F0F;
    x = (x | (x << 2)) & 0x3333_3333_3333_3333;
    (x | (x << 1)) & 0x5555_5555_5555_5555
}

impl Hasher for MortonHasher {
    #[inline]
    fn finish(&self) -> u64 {
        let [a, b] = self.words;
        let m = spread(a) | (spread(b) << 1);
        // High coordinate bits (beyond 32) still separate keys through the tag mix.
        let mix = (a ^ b.rotate_left(32) ^ m).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        (m & 0x01FF_FFFF_FFFF_FFFF) | (mix & 0xFE00_0000_0000_0000)
    }

    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut w = [0u8; 8];
            w[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(w));
        }
    }

    #[inline]
    fn write_u64(&mut self, x: u64) {
        if self.n < 2 {
            self.words[self.n] = x;
        } else {
            self.words[self.n % 2] ^= x.wrapping_mul(0x9E37_79B9_7F4A_7C15);
        }
        self.n += 1;
    }

    #[inline]
    fn write_i64(&mut self, x: i64) {
        self.write_u64(x as u64);
    }
}

/// A hash set of lattice coordinates with locality-preserving hashing.
pub type LatticeSet<K> = std::collections::HashSet<K, MortonBuild>;
/// A hash map from lattice coordinates with locality-preserving hashing.
pub type LatticeMap<K, V> = std::collections::HashMap<K, V, MortonBuild>;

#[cfg(test)]
mod tests {
    use super::*;
    use std::hash::BuildHasher;

    #[test]
    fn neighbours_hash_close_and_distinct_keys_differ() {
        let b = MortonBuild;
        let h = |k: (i64, i64)| b.hash_one(k);
        let mut seen = std::collections::HashSet::new();
        for a in -40..40i64 {
            for c in -40..40i64 {
                assert!(seen.insert(h((a, c))), "collision at {a},{c}");
            }
        }
        // Neighbours differ only in low bits of the bucket index.
        assert!((h((10, 10)) & 0xFFFF) ^ (h((11, 10)) & 0xFFFF) < 8);
    }
}
