// spheres and a stretched torus under an area light: written for algray's POV-Ray comparison (bench/pov_compare.py, tests/test_povray.cpp)
#version 3.7;
global_settings { assumed_gamma 1.0 }
background { color rgb <0.1, 0.1, 0.12> }
camera { location <0, 1.5, -7> look_at <0, 0, 0> right x*image_width/image_height angle 50 }
light_source { <30, 40, -50> color rgb 1 area_light <6, 0, 0>, <0, 6, 0>, 5, 5 }
light_source { <-40, 10, -30> color rgb <0.4, 0.4, 0.5> }
union {
  sphere { <-1.8, 0, 0>, 0.8 pigment { color rgb <0.8, 0.5, 0.3> } //@depth
  }
  sphere { <1.8, 0.3, 0.5>, 0.6 pigment { color rgb <0.3, 0.5, 0.8> } //@depth
  }
  torus { 1, 0.3 pigment { color rgb <0.7, 0.7, 0.7> } scale <1, 2, 1> rotate x*-60 //@depth
  }
}
