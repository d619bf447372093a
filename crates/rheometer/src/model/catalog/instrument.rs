//! Built-in effects of the category instrument: the diameter gauge reads `(1 + g) d + o`. They
//! do not enter the boundary-value problem, only the predicted measurement; each is an
//! error-budget source with a fallback that needs no effect (the measurement model of the
//! principled estimator).

use super::descriptor::{
    one_per_unit, BudgetSource, Category, EffectDescriptor, GaugeColumn, Scope,
};

/// `gauge_scale`: the gauge reads `(1 + g) d + o`, strength `g` \[-\] (`0.03`: 3 % high).
pub const GAUGE_SCALE: EffectDescriptor = EffectDescriptor {
    symbol: "g",
    describe: "diameter gauge scale error, strength = relative error",
    search_range: (-0.3, 0.3),
    physical_range: (-0.1, 0.1),
    independent_check: Some("calibrate the diameter gauge on a wire or fiber of known diameter"),
    budget: Some(BudgetSource {
        key: "gauge_scale_rel",
        unit: "-",
        what: "diameter gauge scale",
        word_unit: ("%", 0.01),
        default: 0.01,
        max: 0.5,
        scope: Scope::Common,
        per_unit: one_per_unit,
        fallback: Some(GaugeColumn::Scale),
        remedy: "calibrate the diameter gauge against wire gauges or add gauge_scale to the fit",
    }),
    ..EffectDescriptor::builtin("gauge_scale", Category::Instrument)
};

/// `gauge_offset`: the gauge reads `(1 + g) d + o`, strength `o` \[µm\].
pub const GAUGE_OFFSET: EffectDescriptor = EffectDescriptor {
    unit: "µm",
    symbol: "o",
    describe: "diameter gauge zero offset, strength = offset",
    search_range: (-50.0, 50.0),
    physical_range: (-20.0, 20.0),
    independent_check: Some("check the diameter gauge's zero on a reference wire"),
    budget: Some(BudgetSource {
        key: "gauge_offset_um",
        unit: "µm",
        what: "diameter gauge offset",
        word_unit: ("µm", 1.0),
        default: 1.0,
        max: 100.0,
        scope: Scope::Common,
        per_unit: one_per_unit,
        fallback: Some(GaugeColumn::OffsetMicrometre),
        remedy: "zero the diameter gauge or add gauge_offset to the fit",
    }),
    ..EffectDescriptor::builtin("gauge_offset", Category::Instrument)
};
