// the Barth sextic as poly { 6, ... }: written for algray's POV-Ray comparison (bench/pov_compare.py, tests/test_povray.cpp)
#version 3.7;
global_settings { assumed_gamma 1.0 }
background { color rgb <0.1, 0.1, 0.12> }
camera { location <0, 0, -9> look_at <0, 0, 0> right x*image_width/image_height angle 45 }
light_source { <30, 40, -50> color rgb 1 }
light_source { <-40, 10, -30> color rgb <0.4, 0.4, 0.5> }
poly { 6,
  <
    0, 0, 0, 0, -27.416407864998742, 0, 0, 10.47213595499958, 0, -4.23606797749979,
    0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
    10.47213595499958, 0, 0, 67.77708763999665, 0, -8.47213595499958, 0, 0, 0, 0,
    -27.416407864998742, 0, -8.47213595499958, 0, 8.47213595499958, 0, 0, 0, 0, 0,
    0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
    0, 0, 0, 0, 0, 0, 0, 0, 0, -27.416407864998742,
    0, -4.23606797749979, 0, 0, 0, 0, 10.47213595499958, 0, -8.47213595499958, 0,
    8.47213595499958, 0, 0, 0, 0, 0, 0, 0, 0, -4.23606797749979,
    0, 8.47213595499958, 0, -4.23606797749979 >
  sturm
  pigment { color rgb <0.95, 0.65, 0.15> }
  clipped_by { sphere { <0, 0, 0>, 3 } }
  rotate <0, 25, 10>
  //@depth
}
