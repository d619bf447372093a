//! Built-in effects of the category material: the VFT law of the zero-rate viscosity off, the
//! viscosity at the reference temperature `T_o` held. Error-budget sources and usable with
//! `fit --with`, but not default candidates of `diagnose`: an error of the temperature
//! dependence of the viscosity is a question for rheometry, not for the spin line.

use super::descriptor::{one_per_unit, BudgetSource, Category, EffectDescriptor, Scope};

const SHEAR_RHEOMETRY: &str =
    "measure the zero-shear viscosity down to the take-up temperatures (shear rheometry)";

/// `vft_b_offset`: VFT parameter `B + ΔB`, the zero-rate viscosity at `T_o` held, strength
/// `ΔB` \[K\].
pub const VFT_B_OFFSET: EffectDescriptor = EffectDescriptor {
    unit: "K",
    symbol: "ΔB",
    describe: "VFT parameter B off (viscosity at T_o held), strength = offset of B",
    search_range: (-1000.0, 1000.0),
    physical_range: (-400.0, 400.0),
    independent_check: Some(SHEAR_RHEOMETRY),
    budget: Some(BudgetSource {
        key: "vft_B_K",
        unit: "K",
        what: "VFT parameter B",
        word_unit: ("K", 1.0),
        default: 30.0,
        max: 2000.0,
        scope: Scope::Common,
        per_unit: one_per_unit,
        fallback: None,
        remedy: "measure the zero-shear viscosity over the spinning temperatures",
    }),
    default_candidate: false,
    ..EffectDescriptor::builtin("vft_b_offset", Category::Material)
};

/// `vft_t_vf_offset`: VFT temperature `T_VF + ΔT_VF`, the level at `T_o` held, strength
/// `ΔT_VF` \[K\].
pub const VFT_T_VF_OFFSET: EffectDescriptor = EffectDescriptor {
    unit: "K",
    symbol: "ΔT_VF",
    describe: "VFT temperature T_VF off (viscosity at T_o held), strength = offset of T_VF",
    // the VFT law is singular at T = T_VF, and the fiber cools towards the air (about
    // 290–300 K against T_VF ≈ 273 K for PMMA): raising T_VF is searched less far
    search_range: (-60.0, 15.0),
    physical_range: (-30.0, 15.0),
    independent_check: Some(SHEAR_RHEOMETRY),
    budget: Some(BudgetSource {
        key: "vft_T_VF_K",
        unit: "K",
        what: "VFT temperature T_VF",
        word_unit: ("K", 1.0),
        default: 3.0,
        max: 100.0,
        scope: Scope::Common,
        per_unit: one_per_unit,
        fallback: None,
        remedy: "measure the zero-shear viscosity over the spinning temperatures",
    }),
    default_candidate: false,
    ..EffectDescriptor::builtin("vft_t_vf_offset", Category::Material)
};
