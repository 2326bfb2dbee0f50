// the Clebsch diagonal cubic as cubic { }: written for algray's POV-Ray comparison (bench/pov_compare.py, tests/test_povray.cpp)
#version 3.7;
global_settings { assumed_gamma 1.0 }
background { color rgb <0.1, 0.1, 0.12> }
camera { location <0, 1.5, -7> look_at <0, 0, 0> right x*image_width/image_height angle 50 }
light_source { <30, 40, -50> color rgb 1 }
light_source { <-40, 10, -30> color rgb <0.4, 0.4, 0.5> }
cubic {
  <
    81, -189, -189, -9, -189, 54, 126, -189, 126, -9,
    81, -189, -9, -189, 126, -9, 81, -9, -9, 1 >
  texture { pigment { color rgb <0.8, 0.3, 0.3> } finish { phong 0.6 phong_size 30 } }
  clipped_by { sphere { <0, 0, 0>, 1 } }
  bounded_by { clipped_by }
  scale 2.2
  rotate <20, 30, 0>
  //@depth
}
