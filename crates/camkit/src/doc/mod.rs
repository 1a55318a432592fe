//! The JSON documents filters exchange besides the toolpath table. Each is a serde type read with
//! [`crate::json`] (errors name the JSON path) and checked by `validate` (errors name the field).

pub mod frame;
pub mod machine;
pub mod model;
pub mod setup;
pub mod tool;

pub use frame::Frame;
pub use machine::Machine;
pub use setup::{Job, Setup};
pub use tool::{Tool, ToolKind};
