// a right-handed camera (right -x): the mirror image: written for algray's POV-Ray comparison (bench/pov_compare.py, tests/test_povray.cpp)
#version 3.7;
global_settings { assumed_gamma 1.0 }
background { color rgb <0.1, 0.1, 0.12> }
camera { location <2, 3, -6> sky y right -x*image_width/image_height up y look_at <0, 0, 0> angle 55 }
light_source { <30, 40, -50> color rgb 1 }
light_source { <-40, 10, -30> color rgb <0.4, 0.4, 0.5> }
union {
  sphere { <2, 0, 0>, 0.7 pigment { color rgb <0.9, 0.2, 0.2> } //@depth
  }
  torus { 1.2, 0.3 pigment { color rgb <0.2, 0.8, 0.3> } rotate z*30 translate <-1, 0.5, 1> //@depth
  }
}
