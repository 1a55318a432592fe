//! `surf-probe-fit`: on-machine measurement of a workpiece (paper 002 §2–4).
//!
//! Geometric least-squares fits of a sphere, plane, circle and cylinder ([`shapes`], on the
//! Levenberg–Marquardt engine of [`lsq`]), reference data with known solutions ([`reference`]),
//! a laser displacement sensor simulator ([`sensor`]), raw sensor records turned into points
//! through the machine's kinematics ([`records`]), the 3-axis raster as a rough Delaunay surface
//! and the 5-axis measuring plan along its normals ([`rough`]), and the fit as the workpiece frame
//! `post-6axis` reads ([`frame`]), and outlines by longitude and latitude mapped onto a fitted
//! sphere ([`globe`]); for free-form parts, a bicubic B-spline height field ([`heightfield`]); a
//! fit's errors against a known element ([`truth`]); the shape document, read strictly ([`document`]).

pub mod document;
pub mod frame;
pub mod globe;
pub mod heightfield;
pub mod lsq;
pub mod ransac;
pub mod records;
pub mod reference;
pub mod rng;
pub mod rough;
pub mod sensor;
pub mod shapes;
pub mod truth;

pub use ransac::Ransac;
pub use shapes::{Fit, FitError, Kind, Options, Robust, Shape, fit};
