//! output submodel (see DESIGN.md).
