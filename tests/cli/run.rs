//! Integration tests of `bulge run`.
#![allow(unused_imports)]
use crate::util;
