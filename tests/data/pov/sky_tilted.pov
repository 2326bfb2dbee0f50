// a tilted camera (sky <1, 2, 0>) on the Steiner surface: written for algray's POV-Ray comparison (bench/pov_compare.py, tests/test_povray.cpp)
#version 3.7;
global_settings { assumed_gamma 1.0 }
background { color rgb <0.1, 0.1, 0.12> }
camera { location <3, 2, -6> sky <1, 2, 0> look_at <0, 0, 0> right x*image_width/image_height angle 48 }
light_source { <30, 40, -50> color rgb 1 }
light_source { <-40, 10, -30> color rgb <0.4, 0.4, 0.5> }
quartic {
  <
    0, 0, 0, 0, 1, 0, 0, 1, 0, 0,
    0, 0, 0, 0, 1, 0, 0, 0, 0, 0,
    0, 0, 0, 1, 0, 0, 0, 0, 0, 0,
    0, 0, 0, 0, 0 >
  pigment { color rgb <0.9, 0.1, 0.2> }
  bounded_by { sphere { <0, 0, 0>, 1 } }
  clipped_by { bounded_by }
  scale 3
  rotate <50, -25, 0>
  //@depth
}
