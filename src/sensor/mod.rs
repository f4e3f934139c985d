//! The sensor submodel: camera geometry, supersampling (in the render),
//! PSF/MTF blur, detector noise and quantisation.

pub mod camera;
pub mod noise;
pub mod psf;
pub mod quantise;
