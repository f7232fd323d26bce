//! The firmware's shared parts: the job (also run by the host's check) and the device glue
//! (stored trees, the instruction clock, output, exit and the panic handler).
#![no_std]

pub mod device;
pub mod job;
