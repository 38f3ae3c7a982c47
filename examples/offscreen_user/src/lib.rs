//! Nothing here: the crate exists for its test, which uses umbra as a dependent crate would.
