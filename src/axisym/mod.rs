//! The exact axisymmetric membrane solution (Adkins & Rivlin 1952, Yang & Feng 1970).
