//! The modifiers of the material data: the VFT parameters `B` (`vft_b`) and `T_VF`
//! (`vft_t_vf`).

pub(super) mod vft_b;
pub(super) mod vft_t_vf;
