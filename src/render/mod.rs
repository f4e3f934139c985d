//! render submodel (see DESIGN.md).
