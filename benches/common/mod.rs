//! What the benches that run a rival alongside share (each bench uses a part of it).
#![allow(dead_code)]

pub mod mujoco;
