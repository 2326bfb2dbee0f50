// a Kummer quartic (mu^2 = 1.3) as quartic { }: written for algray's POV-Ray comparison (bench/pov_compare.py, tests/test_povray.cpp)
#version 3.7;
global_settings { assumed_gamma 1.0 }
background { color rgb <0.1, 0.1, 0.12> }
camera { location <0, 1.5, -7> look_at <0, 0, 0> right x*image_width/image_height angle 50 }
light_source { <30, 40, -50> color rgb 1 }
light_source { <-40, 10, -30> color rgb <0.4, 0.4, 0.5> }
quartic {
  <
    1, 0, 0, 0, -4.823529411764707, 0, 0, 5.411764705882353, 6.8235294117647065, 0.8117647058823534,
    0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
    1, 0, 0, 5.411764705882353, -6.8235294117647065, 0.8117647058823534, 0, 0, 0, 0,
    -0.7058823529411765, 0, 0.8117647058823529, 0, -0.01588235294117647 >
  pigment { color rgb <0.5, 0.8, 0.4> }
  interior_texture { pigment { color rgb <0.8, 0.8, 0.2> } }
  bounded_by { sphere { <0, 0, 0>, 2.6 } }
  clipped_by { bounded_by }
  rotate <-70, 10, 0>
  //@depth
}
