//! The accelerator's description: register map, register-access trait and (issue "The accelerator")
//! the cycle-level model. Only the register map exists so far.
#![no_std]
#![forbid(unsafe_code)]
