//! Firmware for the MorphoSys model: the assembler, the ray tracer's
//! TinyRISC and context sources, and the scene compiler. Knows nothing of
//! host-side rendering.

pub mod asm;
pub mod bsp;
pub mod input;
pub mod scene;
pub mod scene_image;
pub mod tracer;
