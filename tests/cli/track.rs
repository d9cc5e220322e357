//! Integration tests of `bulge track`.
#![allow(unused_imports)]
use crate::util;
