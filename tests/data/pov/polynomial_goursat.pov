// a Goursat quartic as polynomial { xyz(...) }: written for algray's POV-Ray comparison (bench/pov_compare.py, tests/test_povray.cpp)
#version 3.7;
global_settings { assumed_gamma 1.0 }
background { color rgb <0.1, 0.1, 0.12> }
camera { location <0, 1.5, -7> look_at <0, 0, 0> right x*image_width/image_height angle 50 }
light_source { <30, 40, -50> color rgb 1 }
light_source { <-40, 10, -30> color rgb <0.4, 0.4, 0.5> }
polynomial { 4,
    xyz(4,0,0):1, xyz(2,0,0):-2, xyz(0,4,0):1, xyz(0,2,0):-2,
    xyz(0,0,4):1, xyz(0,0,2):-2, xyz(0,0,0):0.8
  pigment { color rgb <0.6, 0.4, 0.9> }
  scale 1.3
  rotate <30, 40, 0>
  clipped_by { box { <-2.2, -2.2, -2.2>, <2.2, 2.2, 1> } }
  //@depth
}
