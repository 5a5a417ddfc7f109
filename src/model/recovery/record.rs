//! The journal's record format: encoding, checked decoding, and reading a whole record back.

use std::io::Read as _;
use std::sync::Arc;

use crate::model::document::DocumentSettings;
use crate::model::maps::MaterialMaps;
use crate::model::project;
use crate::model::tile::{Plane, TILE_TEXELS, Tile};

/// The journal's first bytes.
pub(super) const JOURNAL_MAGIC: &[u8; 8] = b"KPJRNL01";

/// A record's first bytes.
const RECORD_MAGIC: &[u8; 4] = b"KPRC";

/// Largest record read back (bytes): every tile of an 8192^2 map, with room to spare.
const MAX_RECORD_BYTES: u64 = 2 << 30;

/// The next record's payload, if the file holds a whole one whose checksum matches.
pub(super) fn read_record(file: &mut std::fs::File) -> Option<Vec<u8>> {
    let mut head = [0_u8; 12];
    file.read_exact(&mut head).ok()?;
    if &head[..4] != RECORD_MAGIC {
        return None;
    }
    let len = u64::from_le_bytes(head[4..12].try_into().ok()?);
    if len > MAX_RECORD_BYTES {
        return None;
    }
    let mut payload = Vec::new();
    std::io::Read::by_ref(file)
        .take(len)
        .read_to_end(&mut payload)
        .ok()?;
    let mut sum = [0_u8; 4];
    file.read_exact(&mut sum).ok()?;
    (payload.len() as u64 == len && crc32fast::hash(&payload) == u32::from_le_bytes(sum))
        .then_some(payload)
}

/// What one record changes.
pub(super) struct Change {
    pub(super) settings: DocumentSettings,
    pub(super) tiles: Vec<(usize, Tile)>,
}

/// A little-endian reader over a record's bytes.
struct Bytes<'a>(&'a [u8]);

impl Bytes<'_> {
    fn take(&mut self, n: usize) -> Result<&[u8], String> {
        if self.0.len() < n {
            return Err("the record ends early".into());
        }
        let (head, rest) = self.0.split_at(n);
        self.0 = rest;
        Ok(head)
    }

    fn u8(&mut self) -> Result<u8, String> {
        Ok(self.take(1)?[0])
    }

    fn u16(&mut self) -> Result<u16, String> {
        let b = self.take(2)?;
        Ok(u16::from_le_bytes([b[0], b[1]]))
    }

    fn u32(&mut self) -> Result<u32, String> {
        let b = self.take(4)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    fn value<const C: usize>(&mut self) -> Result<[u16; C], String> {
        let mut v = [0_u16; C];
        for c in &mut v {
            *c = self.u16()?;
        }
        Ok(v)
    }

    fn plane<const C: usize>(&mut self) -> Result<Plane<[u16; C]>, String> {
        match self.u8()? {
            0 => Ok(Plane::Uniform(self.value()?)),
            1 => {
                let mut data = Vec::with_capacity(TILE_TEXELS);
                for _ in 0..TILE_TEXELS {
                    data.push(self.value()?);
                }
                Ok(Plane::Data(data.into_boxed_slice()))
            }
            k => Err(format!("unknown plane kind {k}")),
        }
    }
}

/// Decodes and checks a record against the maps it applies to.
pub(super) fn decode_record(record: &[u8], maps: &MaterialMaps) -> Result<Change, String> {
    let mut r = Bytes(record);
    let (w, h) = (r.u32()?, r.u32()?);
    if (w, h) != (maps.width(), maps.height()) {
        return Err("the record is for another map size".into());
    }
    let json_len = r.u32()? as usize;
    let settings: DocumentSettings =
        serde_json::from_slice(r.take(json_len)?).map_err(|e| e.to_string())?;
    let count = r.u32()? as usize;
    let mut tiles = Vec::with_capacity(count.min(maps.tile_count()));
    for _ in 0..count {
        let id = r.u32()? as usize;
        if id >= maps.tile_count() {
            return Err(format!("tile {id} is outside the maps"));
        }
        let kd = r.plane::<3>()?;
        let ks = r.plane::<3>()?;
        let n = match r.plane::<1>()? {
            Plane::Uniform([v]) => Plane::Uniform(v),
            Plane::Data(d) => Plane::Data(d.iter().map(|v| v[0]).collect()),
        };
        let valid = match &n {
            Plane::Uniform(v) => project::valid_n_bits(*v),
            Plane::Data(d) => d.iter().all(|v| project::valid_n_bits(*v)),
        };
        if !valid {
            return Err(format!("tile {id} holds an invalid exponent"));
        }
        tiles.push((id, Tile { kd, ks, n }));
    }
    Ok(Change { settings, tiles })
}

/// Encodes a record: the settings and the tiles, then its length and checksum around it.
pub(super) fn encode_record(
    (w, h): (u32, u32),
    settings: &DocumentSettings,
    tiles: &[(usize, Arc<Tile>)],
) -> Result<Vec<u8>, String> {
    fn plane<const C: usize>(out: &mut Vec<u8>, p: &Plane<[u16; C]>) {
        let values: &[[u16; C]] = match p {
            Plane::Uniform(v) => {
                out.push(0);
                std::slice::from_ref(v)
            }
            Plane::Data(d) => {
                out.push(1);
                d
            }
        };
        for c in values.iter().flatten() {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    let json = serde_json::to_vec(settings).map_err(|e| e.to_string())?;
    let mut payload = Vec::with_capacity(16 + json.len() + tiles.len() * (TILE_TEXELS * 14 + 8));
    payload.extend_from_slice(&w.to_le_bytes());
    payload.extend_from_slice(&h.to_le_bytes());
    payload.extend_from_slice(&(json.len() as u32).to_le_bytes());
    payload.extend_from_slice(&json);
    payload.extend_from_slice(&(tiles.len() as u32).to_le_bytes());
    for (id, tile) in tiles {
        payload.extend_from_slice(&(*id as u32).to_le_bytes());
        plane(&mut payload, &tile.kd);
        plane(&mut payload, &tile.ks);
        let n = match &tile.n {
            Plane::Uniform(v) => Plane::Uniform([*v]),
            Plane::Data(d) => Plane::Data(d.iter().map(|v| [*v]).collect()),
        };
        plane(&mut payload, &n);
    }
    let mut record = Vec::with_capacity(payload.len() + 16);
    record.extend_from_slice(RECORD_MAGIC);
    record.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    record.extend_from_slice(&payload);
    record.extend_from_slice(&crc32fast::hash(&payload).to_le_bytes());
    Ok(record)
}
