//! The largest image a TIFF-structured raw file (DNG, CR2, NEF, ARW, PEF, …) claims, read
//! from its image file directories before any pixel is decoded (TIFF 6.0, section 2: the
//! 8-byte header, then IFDs of 12-byte entries; `SubIFDs`, tag 330, as DNG and TIFF/EP use
//! them). The raw decoder allocates an image of the claimed size first, so a file that
//! claims a huge one is refused here against the pixel limit instead.

/// IFDs followed at most (main chain and SubIFDs together), against loops.
const MAX_IFDS: usize = 64;
/// Entries read per IFD at most.
const MAX_ENTRIES: usize = 4096;

/// The largest width × height any IFD of the TIFF file `bytes` claims; `None` when `bytes`
/// is not a TIFF file or claims no image.
pub fn largest_claimed_pixels(bytes: &[u8]) -> Option<u64> {
    let little = match bytes.get(..4)? {
        b"II*\0" => true,
        b"MM\0*" => false,
        _ => return None,
    };
    let u16_at = |at: usize| -> Option<u64> {
        let b: [u8; 2] = bytes.get(at..at + 2)?.try_into().ok()?;
        Some(u64::from(if little {
            u16::from_le_bytes(b)
        } else {
            u16::from_be_bytes(b)
        }))
    };
    let u32_at = |at: usize| -> Option<u64> {
        let b: [u8; 4] = bytes.get(at..at + 4)?.try_into().ok()?;
        Some(u64::from(if little {
            u32::from_le_bytes(b)
        } else {
            u32::from_be_bytes(b)
        }))
    };
    let mut pending = vec![u32_at(4)?];
    let mut seen = Vec::new();
    let mut largest = None;
    while let Some(offset) = pending.pop() {
        if offset == 0 || seen.contains(&offset) || seen.len() >= MAX_IFDS {
            continue;
        }
        seen.push(offset);
        let start = usize::try_from(offset).ok()?;
        let Some(count) = u16_at(start) else { continue };
        let (mut width, mut height) = (None, None);
        for k in 0..(count as usize).min(MAX_ENTRIES) {
            let entry = start + 2 + 12 * k;
            let (Some(tag), Some(kind), Some(n)) =
                (u16_at(entry), u16_at(entry + 2), u32_at(entry + 4))
            else {
                break;
            };
            // A SHORT (3) value sits in the entry's first two bytes, a LONG (4) or IFD
            // (13) in its four.
            let value = |i: u64| match kind {
                3 => u16_at(entry + 8 + 2 * i as usize),
                4 | 13 if n == 1 => u32_at(entry + 8),
                4 | 13 => u32_at(usize::try_from(u32_at(entry + 8)?).ok()? + 4 * i as usize),
                _ => None,
            };
            match tag {
                256 => width = value(0),
                257 => height = value(0),
                330 => pending.extend((0..n.min(MAX_IFDS as u64)).filter_map(value)),
                _ => {}
            }
        }
        if let (Some(w), Some(h)) = (width, height) {
            largest = Some(largest.unwrap_or(0).max(w.saturating_mul(h)));
        }
        if let Some(next) = u32_at(start + 2 + 12 * count as usize) {
            pending.push(next);
        }
    }
    largest
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A little-endian TIFF with one IFD of `width` × `height` (LONG values) whose
    /// SubIFDs tag points at a second IFD of `sub` × `sub`.
    fn tiff(width: u32, height: u32, sub: u32) -> Vec<u8> {
        let mut b = b"II*\0".to_vec();
        b.extend(8u32.to_le_bytes());
        let entry = |b: &mut Vec<u8>, tag: u16, kind: u16, value: u32| {
            b.extend(tag.to_le_bytes());
            b.extend(kind.to_le_bytes());
            b.extend(1u32.to_le_bytes());
            b.extend(value.to_le_bytes());
        };
        // IFD 0 at 8: three entries (2 + 36 bytes), next-IFD pointer (4): the sub-IFD at 50.
        b.extend(3u16.to_le_bytes());
        entry(&mut b, 256, 4, width);
        entry(&mut b, 257, 4, height);
        entry(&mut b, 330, 4, 50);
        b.extend(0u32.to_le_bytes());
        assert_eq!(b.len(), 50);
        b.extend(2u16.to_le_bytes());
        entry(&mut b, 256, 3, sub);
        entry(&mut b, 257, 3, sub);
        b.extend(0u32.to_le_bytes());
        b
    }

    #[test]
    fn the_largest_image_of_the_main_chain_and_sub_ifds_is_found() {
        assert_eq!(
            largest_claimed_pixels(&tiff(160, 120, 4000)),
            Some(16_000_000)
        );
        assert_eq!(
            largest_claimed_pixels(&tiff(6000, 4000, 100)),
            Some(24_000_000)
        );
        assert_eq!(
            largest_claimed_pixels(&tiff(1, 1, 60_000)),
            Some(3_600_000_000)
        );
    }

    #[test]
    fn anything_else_or_a_broken_structure_claims_nothing_and_never_panics() {
        assert_eq!(largest_claimed_pixels(b"\xFF\xD8\xFF\xE0"), None);
        assert_eq!(largest_claimed_pixels(b"II*\0"), None);
        let whole = tiff(160, 120, 4000);
        for cut in 0..whole.len() {
            let _ = largest_claimed_pixels(&whole[..cut]);
        }
        // An IFD pointing at itself ends.
        let mut looped = whole.clone();
        looped[46..50].copy_from_slice(&8u32.to_le_bytes());
        assert_eq!(largest_claimed_pixels(&looped), Some(16_000_000));
    }
}
