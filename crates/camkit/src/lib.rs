//! `camkit`: the shared library of the CAM toolkit's filters.
//!
//! Geometry on nalgebra ([`geom`]), the toolpath table every filter reads and writes
//! ([`table`]), a G-code reader and writer for the 3-axis subset ([`gcode`]), JSON documents
//! ([`json`], [`doc`]), one error type with file/line/column ([`error`]), named tolerances
//! ([`tol`]), whole-or-nothing output and the common command-line pieces ([`io`], [`cli`],
//! [`report`]), and SVG plots ([`svg`]). Nothing here is specific to one filter.

pub mod budget;
pub mod cli;
pub mod collide;
pub mod contour;
pub mod doc;
pub mod dxf;
pub mod error;
pub mod gcode;
pub mod geom;
pub mod io;
pub mod json;
pub mod kinematics;
pub mod model;
pub mod num;
pub mod report;
pub mod svg;
pub mod table;
pub mod tol;

pub use error::{Error, ErrorKind, Location, Result};
