//! The refits behind a diagnosis: one candidate effect scanned over its search range
//! ([`scan`]), two fitted jointly ([`pair`]), and each fitted effect's strength per experiment
//! (`consistency`).

pub(crate) mod consistency;
pub(crate) mod pair;
pub(crate) mod scan;
