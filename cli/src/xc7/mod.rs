//! What is particular to a Xilinx 7-series board's build beyond the Vivado files of
//! [`crate::fpga`]: [`mmcm`] makes the fabric clock when it is not the oscillator's.

pub mod mmcm;

pub use mmcm::{solve_mmcm, MmcmSetting};
