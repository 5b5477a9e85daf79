//! Recording: contact events (filled by the layer) and time series (sampled by the driver).

pub mod events;
pub mod series;
