// POV-Ray 3.7 peer of scenes/prism_bk7.json (hand-written; bench/spectral_bench.cpp renders it).
// eikon's world is right-handed, POV-Ray's left-handed: a point (x, y, z) of the eikon scene is
// <x, y, -z> here. Equilateral N-BK7 prism, 10 mm faces, 12 mm tall along y, apex toward eikon
// +z; camera 100 mm away near minimum deviation (vertical fov 6° = horizontal 7.996° at 4:3); a
// thin emissive slit (0.088° × 2.8°, radiance 40) far away where d-line light is deviated into
// the camera; sky radiance 0.02 — the latlong EXR of the eikon scene, as geometry.
// Dispersion: ior = n_d of N-BK7 (1.5168); POV-Ray's `dispersion` is the ratio of the violet to
// the red index; we give n_F/n_C = 1.522376/1.514322 = 1.005319 as the issue asks (POV-Ray
// spreads it over its own visible range, so the rendered spread is close to, not equal to,
// N-BK7's). dispersion_samples 16 = eikon's default 16 wavelengths.
#version 3.7;
global_settings {
  assumed_gamma 1.0
  max_trace_level 10
  photons { count 20000 autostop 0 jitter 0.4 }
}
background { rgb 0.02 }
camera {
  perspective
  location <94.3658, 0, 33.0923>
  look_at <0, 0, 0>
  right x * image_width / image_height
  angle 7.996
}
#declare H = 10 * cos(radians(30));
prism {
  linear_sweep linear_spline -6, 6, 4,
  <0, -2 / 3 * H>, <-5, H / 3>, <5, H / 3>, <0, -2 / 3 * H>
  pigment { rgbf <1, 1, 1, 1> }
  finish { ambient 0 diffuse 0 reflection { 0.0, 1.0 fresnel on } conserve_energy }
  interior { ior 1.5168 dispersion 1.005319 dispersion_samples 16 }
  photons { target reflection on refraction on }
}
// The slit: 10 m away along eikon (-cos 19.3234°, 0, -sin 19.3234°) = POV <-0.94366, 0, 0.33092>.
box {
  <-1, -244.4, -7.68>, <1, 244.4, 7.68>
  rotate y * 19.3234
  translate <-9436.6, 0, 3309.2>
  pigment { rgb 1 }
  finish { ambient 0 diffuse 0 emission 40 }
  no_shadow
  photons { collect off }
}
light_source { <-9436.6, 0, 3309.2> rgb 1 photons { refraction on reflection on } }
