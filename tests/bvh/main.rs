//! The BVH reader and writer, and the foundation round trip through them.
//!
//! One test binary (`cargo test --release --test bvh NAME`), a module per file.

#[path = "../common/mod.rs"]
mod common;

mod foundation_roundtrip;
mod reader;
mod roundtrip;
mod writer;
