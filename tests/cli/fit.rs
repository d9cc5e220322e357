//! Integration tests of `bulge fit`.
#![allow(unused_imports)]
use crate::util;
