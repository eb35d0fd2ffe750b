# eta* along axis 1 at each axis-0 node: field points (dem) and the closed form
set datafile separator ','
set grid
set key outside right
set xlabel 'stroke X / m'
set ylabel 'reduced loss factor {/Symbol h}*'
set title 'link_medium: effective field (dem) and closed form' noenhanced
set yrange [0:*]
do for [t in 'pngcairo svg'] {
  set terminal t size 1000,600 enhanced font 'Sans,11'
  set output (t eq 'svg') ? 'field_cuts.svg' : 'field_cuts.png'
  plot for [i=0:1] 'field_cuts_formula.csv' index i using 2:3 with lines dt 2 lw 1.5 lc i+1 title sprintf('closed form, f = %g Hz', word('3.6 4.3 ', i+1)+0), \
       for [i=0:1] 'field_cuts_points.csv' index i using 2:3:4 with yerrorlines pt 7 lw 2 lc i+1 title sprintf('dem, f = %g Hz', word('3.6 4.3 ', i+1)+0)
}
