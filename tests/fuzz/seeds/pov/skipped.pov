// What the reader skips with warnings, and declarations it reads
#version 3.7;
#include "colors.inc"
#declare R = 1.5;
#declare Centre = <0, R/2, 0>;
#declare Tint = color rgbf <0.2, 0.4, 0.6, 0.3>;
global_settings { assumed_gamma 2.2 max_trace_level 5 }
camera { perspective location <1, 2, -8> direction z right x*4/3 up y sky y look_at Centre angle 40 }
light_source { <10, 10, -10> colour rgb 1 spotlight point_at 0 }
plane { y, -2 pigment { checker color rgb 1 color rgb 0 } }
fog { distance 10 color rgb 0.5 }
sphere { Centre, R
  texture { pigment { Tint } normal { bumps 0.3 } finish { ambient 0.2 reflection 0.3 phong 1 } }
  no_shadow hollow
  scale <1, 1, 1> rotate y*10 translate -x
}
