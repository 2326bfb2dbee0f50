camera { orthographic location <0, 0, -10> look_at 0 right 8*x up 6*y }
light_source { <0, 10, -10> color rgb <1, 0.9, 0.8> area_light <2, 0, 0>, <0, 2, 0>, 4, 4 adaptive 1 jitter }
background { rgb <0.2, 0.2, 0.3> }
union {
  torus { 2, 0.3 pigment { rgb <1, 0, 0> } rotate x*90 }
  polynomial { 2, xyz(2,0,0):1, xyz(0,2,0):1, xyz(0,0,2):1, xyz(0,0,0):-0.5 inverse clipped_by { box { -3, 3 } } }
  translate <0.5, 0, 0>
}
