//! applesim: apple contact in fruit-handling lines.
#![warn(missing_docs)]

pub mod contact;
pub mod layer;
pub mod math;
pub mod record;
