// The CORDIC ROM of hdl-model/src/cordic/rom.rs, as constant functions: atan 2^-i, the inverse
// gains 1/K_n and pi/2, each Q0.62, rounded at elaboration to the word a W-bit design holds
// (format::rom_round). Included inside a module, so every unit rounds to its own width.

function [63:0] atan_q62(input integer i);
    case (i)
        0:  atan_q62 = 64'h3243_f6a8_885a_3000;
        1:  atan_q62 = 64'h1dac_6705_61bb_4f00;
        2:  atan_q62 = 64'h0fad_bafc_9640_6e80;
        3:  atan_q62 = 64'h07f5_6ea6_ab0b_db80;
        4:  atan_q62 = 64'h03fe_ab76_e59f_bd40;
        5:  atan_q62 = 64'h01ff_d55b_ba97_6250;
        6:  atan_q62 = 64'h00ff_faaa_dddb_94d8;
        7:  atan_q62 = 64'h007f_ff55_56ee_ea5c;
        8:  atan_q62 = 64'h003f_ffea_aab7_776e;
        9:  atan_q62 = 64'h001f_fffd_5555_bbbc;
        10: atan_q62 = 64'h000f_ffff_aaaa_adde;
        11: atan_q62 = 64'h0007_ffff_f555_556f;
        12: atan_q62 = 64'h0003_ffff_feaa_aaac;
        13: atan_q62 = 64'h0001_ffff_ffd5_5555;
        14: atan_q62 = 64'h0000_ffff_fffa_aaab;
        15: atan_q62 = 64'h0000_7fff_ffff_5555;
        16: atan_q62 = 64'h0000_3fff_ffff_eaab;
        17: atan_q62 = 64'h0000_1fff_ffff_fd55;
        18: atan_q62 = 64'h0000_0fff_ffff_ffab;
        19: atan_q62 = 64'h0000_07ff_ffff_fff5;
        20: atan_q62 = 64'h0000_03ff_ffff_ffff;
        default: atan_q62 = 64'h0000_0200_0000_0000 >> (i - 21);
    endcase
endfunction

function [63:0] inv_gain_q62(input integer n);
    case (n)
        0:  inv_gain_q62 = 64'h4000_0000_0000_0000;
        1:  inv_gain_q62 = 64'h2d41_3ccc_fe77_9800;
        2:  inv_gain_q62 = 64'h287a_26c4_9092_1e00;
        3:  inv_gain_q62 = 64'h2744_c374_daf4_6c00;
        4:  inv_gain_q62 = 64'h26f7_2283_bd67_fc00;
        5:  inv_gain_q62 = 64'h26e3_b583_05dd_ea00;
        6:  inv_gain_q62 = 64'h26de_d9f5_7b2c_3e00;
        7:  inv_gain_q62 = 64'h26dd_a30d_3e4f_d200;
        8:  inv_gain_q62 = 64'h26dd_5552_e164_2000;
        9:  inv_gain_q62 = 64'h26dd_41e4_454d_a200;
        10: inv_gain_q62 = 64'h26dd_3d08_9dfa_4800;
        11: inv_gain_q62 = 64'h26dd_3bd1_b420_9600;
        12: inv_gain_q62 = 64'h26dd_3b83_f9a9_dc00;
        13: inv_gain_q62 = 64'h26dd_3b70_8b0c_2a00;
        14: inv_gain_q62 = 64'h26dd_3b6b_af64_bc00;
        15: inv_gain_q62 = 64'h26dd_3b6a_787a_e000;
        16: inv_gain_q62 = 64'h26dd_3b6a_2ac0_6a00;
        17: inv_gain_q62 = 64'h26dd_3b6a_1751_ca00;
        18: inv_gain_q62 = 64'h26dd_3b6a_1276_2400;
        19: inv_gain_q62 = 64'h26dd_3b6a_113f_3a00;
        20: inv_gain_q62 = 64'h26dd_3b6a_10f1_8000;
        21: inv_gain_q62 = 64'h26dd_3b6a_10de_1000;
        22: inv_gain_q62 = 64'h26dd_3b6a_10d9_3600;
        23: inv_gain_q62 = 64'h26dd_3b6a_10d7_fe00;
        24: inv_gain_q62 = 64'h26dd_3b6a_10d7_b000;
        25: inv_gain_q62 = 64'h26dd_3b6a_10d7_9c00;
        default: inv_gain_q62 = 64'h26dd_3b6a_10d7_9800;
    endcase
endfunction

localparam [63:0] HALF_PI_Q62 = 64'h6487_ed51_10b4_6000;

// A Q0.62 constant rounded to `frac` fraction bits (round half up, as format::rom_round).
function [63:0] rom_round(input [63:0] q62, input integer frac);
    reg [63:0] half;
    begin
        half = 64'd1 << (62 - frac - 1);
        rom_round = (q62 + half) >> (62 - frac);
    end
endfunction
