//! Built-in effects of the category physics: the viscosity law's strain thinning, radiation,
//! the air's speed and temperature profiles, the Nusselt law's scale.

use super::descriptor::{
    Category, EffectDescriptor, Install, ShapeParameter, ShapeScan, StrengthMap,
};

/// Default decay length `ℓ` \[m\] of the aspirator co-flow `V exp(−(L − s)/ℓ)`.
pub const DEFAULT_COFLOW_DECAY_LENGTH: f64 = 0.1;

/// Default decay length `ℓ` \[m\] of the warm-air profile `ΔT exp(−s/ℓ)`.
pub const DEFAULT_WARM_AIR_DECAY_LENGTH: f64 = 0.05;

/// Default onset position `s₀` \[m\] of the co-flow along the line.
pub const DEFAULT_COFLOW_LINE_ONSET: f64 = 0.2;

/// Default (start) ramp width `w` \[m\] of the co-flow along the line.
pub const DEFAULT_COFLOW_LINE_RAMP_WIDTH: f64 = 0.02;

/// What decides radiation and the convective heat transfer (the Nusselt law's scale): the
/// fiber's temperature along the line, which both set.
pub const FIBER_TEMPERATURE_CHECK: &str = "measure the fiber temperature along the line (an \
                                           infrared pyrometer): radiation and the heat \
                                           transfer set how fast it cools";

/// `κ = ln(K / 1 Pa)` \[-\] at which the strain-thinning direction of a Newtonian model is taken
/// (the middle of the default κ range (7, 20)).
pub const STRAIN_THINNING_REFERENCE_KAPPA: f64 = 13.5;

/// `strain_thinning`: the Carreau-type law instead of the Newtonian one, strength `1 − n` \[-\].
/// Its derivative at `s = 0` is `−∂μ_e/∂n = −½ μ_e0 ln(1 + De² (μ_e0 ε̇/K̃)²)`, which depends on
/// the stress scale `K = e^κ` the Newtonian fit leaves undetermined: the linearised score uses
/// `κ` = [`STRAIN_THINNING_REFERENCE_KAPPA`], a refit frees both `n` and `κ`.
pub const STRAIN_THINNING: EffectDescriptor = EffectDescriptor {
    name: "strain_thinning",
    model_param: "n",
    unit: "-",
    symbol: "1 - n",
    describe: "strain thinning (Carreau-type law), strength 1 - n",
    category: Category::Physics,
    neutral: 0.0,
    search_range: (0.0, 1.0),
    physical_range: (0.0, 1.0),
    shapes: &[],
    map: StrengthMap::OneMinus,
    fit_parameters: 2,
    independent_check: None,
    budget: None,
    install: Install::Law {
        reference: [1.0, STRAIN_THINNING_REFERENCE_KAPPA],
    },
    default_candidate: true,
};

/// `radiation`: grey-body radiation `−π d ε σ (T⁴ − T_air⁴)`, strength = emissivity `ε` \[-\].
pub const RADIATION: EffectDescriptor = EffectDescriptor {
    symbol: "ε",
    describe: "thermal radiation, strength = emissivity",
    search_range: (-0.5, 2.0),
    physical_range: (0.0, 1.0),
    independent_check: Some(FIBER_TEMPERATURE_CHECK),
    ..EffectDescriptor::builtin("radiation", Category::Physics)
};

/// The co-flow's decay length `ℓ` \[m\].
pub const COFLOW_DECAY: ShapeParameter = ShapeParameter {
    name: "decay_length",
    model_param: "air_coflow.decay_length",
    unit: "m",
    default: DEFAULT_COFLOW_DECAY_LENGTH,
    bounds: (0.01, 1.5),
    max_per_length: Some(1.5),
    fitted_with_strength: true,
    scanned: true,
    // 0.15 ×: an aspirator jet within a few centimetres of the take-up
    scan: ShapeScan::OfDefault(&[0.15, 0.4, 1.0, 2.5]),
    describe: "decay length of the co-flow away from the take-up",
};

/// The co-flow's tail `r` \[-\]: a discrete choice, not fitted.
pub const COFLOW_TAIL: ShapeParameter = ShapeParameter {
    name: "tail",
    model_param: "air_coflow.tail",
    unit: "-",
    default: 0.0,
    bounds: (0.0, 1.0),
    max_per_length: None,
    fitted_with_strength: false,
    scanned: true,
    scan: ShapeScan::Choices(&[0.0, 0.5]),
    describe: "tail r of the co-flow's decay away from the take-up, (1 + r z/l)^(-1/r): \
               0 exponential, 0.5 inverse square (entrainment towards a sink), 1 inverse (a jet)",
};

/// `air_coflow`: aspirator co-flow near the take-up, `v_air = V (1 + r (L − s)/ℓ)^(−1/r)`,
/// strength = amplitude `V` \[m/s\].
pub const AIR_COFLOW: EffectDescriptor = EffectDescriptor {
    unit: "m/s",
    symbol: "V",
    describe: "aspirator air co-flow near the take-up, strength = air speed amplitude",
    search_range: (-100.0, 600.0),
    physical_range: (-50.0, 400.0),
    shapes: &[COFLOW_DECAY, COFLOW_TAIL],
    independent_check: Some(
        "measure the air speed next to the fiber near the take-up (a hot-wire anemometer)",
    ),
    ..EffectDescriptor::builtin("air_coflow", Category::Physics)
};

/// The line co-flow's onset `s₀` \[m\].
pub const COFLOW_LINE_ONSET: ShapeParameter = ShapeParameter {
    name: "onset",
    model_param: "air_coflow_line.onset",
    unit: "m",
    default: DEFAULT_COFLOW_LINE_ONSET,
    bounds: (0.0, 2.0),
    max_per_length: Some(1.0),
    fitted_with_strength: true,
    scanned: true,
    scan: ShapeScan::OfLength(&[0.3, 0.5, 0.7]),
    describe: "position where the co-flow along the line sets in",
};

/// The line co-flow's ramp width `w` \[m\].
pub const COFLOW_LINE_RAMP: ShapeParameter = ShapeParameter {
    name: "ramp_width",
    model_param: "air_coflow_line.ramp_width",
    unit: "m",
    default: DEFAULT_COFLOW_LINE_RAMP_WIDTH,
    bounds: (0.002, 0.5),
    max_per_length: Some(1.0),
    fitted_with_strength: true,
    scanned: false,
    scan: ShapeScan::Default,
    describe: "width of the logistic ramp of the co-flow along the line",
};

/// `air_coflow_line`: co-flow along the line after an onset, `v_air = V / (1 + exp(−(s −
/// s₀)/w))`, strength = speed `V` \[m/s\].
pub const AIR_COFLOW_LINE: EffectDescriptor = EffectDescriptor {
    unit: "m/s",
    symbol: "V",
    describe: "air co-flow along the spin line after an onset position, strength = air speed",
    search_range: (-100.0, 600.0),
    physical_range: (-50.0, 400.0),
    shapes: &[COFLOW_LINE_ONSET, COFLOW_LINE_RAMP],
    independent_check: Some(
        "measure the air speed next to the fiber along the line (a hot-wire anemometer)",
    ),
    ..EffectDescriptor::builtin("air_coflow_line", Category::Physics)
};

/// The warm air's decay length `ℓ` \[m\].
pub const WARM_AIR_DECAY: ShapeParameter = ShapeParameter {
    name: "decay_length",
    model_param: "air_temperature_profile.decay_length",
    unit: "m",
    default: DEFAULT_WARM_AIR_DECAY_LENGTH,
    bounds: (0.005, 1.0),
    max_per_length: Some(1.0),
    fitted_with_strength: true,
    scanned: true,
    scan: ShapeScan::OfDefault(&[0.4, 1.0, 2.5]),
    describe: "decay length of the warm air below the nozzle",
};

/// `air_temperature_profile`: warm air near the nozzle, `T_air(s) = T_air + ΔT exp(−s/ℓ)`,
/// strength = excess `ΔT` \[K\].
pub const AIR_TEMPERATURE_PROFILE: EffectDescriptor = EffectDescriptor {
    unit: "K",
    symbol: "ΔT",
    describe: "warm air near the nozzle, strength = air temperature excess",
    search_range: (-60.0, 600.0),
    physical_range: (-50.0, 400.0),
    shapes: &[WARM_AIR_DECAY],
    independent_check: Some(
        "measure the air temperature next to the fiber below the die (a thermocouple moved along the line)",
    ),
    ..EffectDescriptor::builtin("air_temperature_profile", Category::Physics)
};

/// `nusselt_scale`: the Nusselt law `𝒩 → (1 + s) 𝒩`, strength `s` \[-\] (the factor of the
/// base model's convection term).
pub const NUSSELT_SCALE: EffectDescriptor = EffectDescriptor {
    symbol: "s",
    describe: "scale on the Nusselt law, strength s in (1 + s) Nu",
    search_range: (-0.9, 3.0),
    physical_range: (-0.5, 1.0),
    map: StrengthMap::OnePlus,
    independent_check: Some(FIBER_TEMPERATURE_CHECK),
    ..EffectDescriptor::builtin("nusselt_scale", Category::Physics)
};
