//! kapaint: paint per-texel Phong reflectance and preview it with a derived ambient term.

pub mod reflectance;
