//! scene submodel (see DESIGN.md).
