//! atmos submodel (see DESIGN.md).
