//! radiometry submodel (see DESIGN.md).
