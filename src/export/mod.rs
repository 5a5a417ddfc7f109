//! Exporting compact texture sets (issue 6). So far: the choice of `n`'s encoding by the
//! `k_a` error it causes ([`encoding`]).

pub mod encoding;
