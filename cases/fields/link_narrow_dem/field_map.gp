# heat map of eta* over the two axes, motion modes marked (dem)
set view map
set pm3d map interpolate 0,0
set palette rgb 33,13,10
set xlabel 'frequency f / Hz'
set ylabel 'stroke X / m'
set cblabel 'reduced loss factor {/Symbol h}*'
set title 'link_narrow: effective field (dem)' noenhanced
set label 1 'RC/BC rolling/bouncing collect-and-collide, SP sub-peak orbit, SC scattered, SL solid-like, LF/GF local/global fluidisation, DC decoupled' at screen 0.5, 0.02 center font ',9'
set bmargin 5
set xrange [3.572:4.328]
set yrange [-0.000688:0.025988]
do for [t in 'pngcairo svg'] {
  set terminal t size 1000,700 enhanced font 'Sans,11'
  set output (t eq 'svg') ? 'field_map.svg' : 'field_map.png'
  splot 'field_map.dat' using 1:2:3 with pm3d notitle, '' using 1:2:3:4 with labels tc rgb 'black' font ',10' notitle
}
