//! sensor submodel (see DESIGN.md).
