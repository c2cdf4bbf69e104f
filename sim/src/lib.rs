//! Verilator co-simulation of the generated core against the model. Not built yet: see issue 3.
