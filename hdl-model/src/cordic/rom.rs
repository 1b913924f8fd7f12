//! ROM contents of the CORDIC: arctangents of 2^-i and the inverse gains, as Q0.62 integers.
//!
//! Generated once from f64 (`atan(2^-i)`, `1/Π_{i<n} √(1+2^-2i)`); the datapath rounds them to its
//! word width when it is configured ([`crate::format::rom_round`]), as a W-bit ROM would hold them.
//! 53 significant bits of f64 are far more than the 30 fraction bits any width uses.

/// atan(2^-i), i = 0..32, Q0.62.
pub const ATAN_Q62: [u64; 32] = [
    0x3243_f6a8_885a_3000,
    0x1dac_6705_61bb_4f00,
    0x0fad_bafc_9640_6e80,
    0x07f5_6ea6_ab0b_db80,
    0x03fe_ab76_e59f_bd40,
    0x01ff_d55b_ba97_6250,
    0x00ff_faaa_dddb_94d8,
    0x007f_ff55_56ee_ea5c,
    0x003f_ffea_aab7_776e,
    0x001f_fffd_5555_bbbc,
    0x000f_ffff_aaaa_adde,
    0x0007_ffff_f555_556f,
    0x0003_ffff_feaa_aaac,
    0x0001_ffff_ffd5_5555,
    0x0000_ffff_fffa_aaab,
    0x0000_7fff_ffff_5555,
    0x0000_3fff_ffff_eaab,
    0x0000_1fff_ffff_fd55,
    0x0000_0fff_ffff_ffab,
    0x0000_07ff_ffff_fff5,
    0x0000_03ff_ffff_ffff,
    0x0000_0200_0000_0000,
    0x0000_0100_0000_0000,
    0x0000_0080_0000_0000,
    0x0000_0040_0000_0000,
    0x0000_0020_0000_0000,
    0x0000_0010_0000_0000,
    0x0000_0008_0000_0000,
    0x0000_0004_0000_0000,
    0x0000_0002_0000_0000,
    0x0000_0001_0000_0000,
    0x0000_0000_8000_0000,
];

/// 1/K_n, the inverse CORDIC gain after n iterations, n = 0..=32, Q0.62.
pub const INV_GAIN_Q62: [u64; 33] = [
    0x4000_0000_0000_0000,
    0x2d41_3ccc_fe77_9800,
    0x287a_26c4_9092_1e00,
    0x2744_c374_daf4_6c00,
    0x26f7_2283_bd67_fc00,
    0x26e3_b583_05dd_ea00,
    0x26de_d9f5_7b2c_3e00,
    0x26dd_a30d_3e4f_d200,
    0x26dd_5552_e164_2000,
    0x26dd_41e4_454d_a200,
    0x26dd_3d08_9dfa_4800,
    0x26dd_3bd1_b420_9600,
    0x26dd_3b83_f9a9_dc00,
    0x26dd_3b70_8b0c_2a00,
    0x26dd_3b6b_af64_bc00,
    0x26dd_3b6a_787a_e000,
    0x26dd_3b6a_2ac0_6a00,
    0x26dd_3b6a_1751_ca00,
    0x26dd_3b6a_1276_2400,
    0x26dd_3b6a_113f_3a00,
    0x26dd_3b6a_10f1_8000,
    0x26dd_3b6a_10de_1000,
    0x26dd_3b6a_10d9_3600,
    0x26dd_3b6a_10d7_fe00,
    0x26dd_3b6a_10d7_b000,
    0x26dd_3b6a_10d7_9c00,
    0x26dd_3b6a_10d7_9800,
    0x26dd_3b6a_10d7_9800,
    0x26dd_3b6a_10d7_9800,
    0x26dd_3b6a_10d7_9800,
    0x26dd_3b6a_10d7_9800,
    0x26dd_3b6a_10d7_9800,
    0x26dd_3b6a_10d7_9800,
];

/// π/2 in Q0.62 (the coarse rotation step).
pub const HALF_PI_Q62: u64 = 0x6487_ed51_10b4_6000;
