//! Heights -> stress and strain (paper 000, eqs 18-25).
