// an orthographic camera on a cyclide-like quartic: written for algray's POV-Ray comparison (bench/pov_compare.py, tests/test_povray.cpp)
#version 3.7;
global_settings { assumed_gamma 1.0 }
background { color rgb <0.1, 0.1, 0.12> }
camera { orthographic location <0, 0, -10> look_at <0, 0, 0> right 6*x*image_width/image_height up 6*y }
light_source { <30, 40, -50> color rgb 1 }
light_source { <-40, 10, -30> color rgb <0.4, 0.4, 0.5> }
polynomial { 4,
    xyz(4,0,0):1, xyz(2,2,0):2, xyz(2,0,2):2, xyz(2,0,0):-11,
    xyz(1,0,0):6, xyz(0,4,0):1, xyz(0,2,2):2, xyz(0,2,0):-6,
    xyz(0,0,4):1, xyz(0,0,2):-2
  pigment { color rgb <0.4, 0.7, 0.8> }
  clipped_by { sphere { <0, 0, 0>, 2.5 } }
  rotate <-30, 20, 0>
  //@depth
}
