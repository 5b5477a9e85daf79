//! Recording: contact events (filled by the layer), time series (sampled by the driver) and
//! slip/roll transitions (detected by the driver from the layer's contact slips).

pub mod events;
pub mod probe;
pub mod series;
pub mod transitions;
