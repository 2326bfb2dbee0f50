// a sphere clipped by a box, moved: written for algray's POV-Ray comparison (bench/pov_compare.py, tests/test_povray.cpp)
#version 3.7;
global_settings { assumed_gamma 1.0 }
background { color rgb <0.1, 0.1, 0.12> }
camera { location <0, 1.5, -7> look_at <0, 0, 0> right x*image_width/image_height angle 50 }
light_source { <30, 40, -50> color rgb 1 }
light_source { <-40, 10, -30> color rgb <0.4, 0.4, 0.5> }
sphere { <0, 0, 0>, 2
  pigment { color rgb <0.3, 0.7, 0.9> }
  clipped_by { box { <-1.5, -3, -3>, <3, 1.2, 3> } }
  translate <0.5, 0, 0>
  //@depth
}
