//! rust-hdl description of the snapgen motion core. Not built yet: see issue 3.
