//! Integration tests of `bulge stress`.
#![allow(unused_imports)]
use crate::util;
