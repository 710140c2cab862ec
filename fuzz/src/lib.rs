//! The fuzz targets' bodies, in one file the main crate's `tests/fuzz_corpus.rs` also
//! includes to replay the committed corpora under `cargo test`.

pub mod targets;
