//! Collision checking of programs: the stock the program has not cut yet ([`material`]) and the
//! walls of a 2.5-D part ([`walls`]), measured exactly where they can be.

pub mod closed_form;
pub mod material;
pub mod solid;
pub mod walls;
