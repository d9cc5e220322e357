//! Integration tests of `bulge simulate`.
#![allow(unused_imports)]
use crate::util;
