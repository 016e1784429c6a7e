set terminal pngcairo size 1100,700 noenhanced
if (!exists('plot_file')) plot_file = 'docs/tradeoff_soft.png'
set output plot_file
set title 'Error against render time, scene soft'
set xlabel 'render time (ms, warm)'
set ylabel 'RMSE against the converged reference'
set logscale xy
set grid
set key top right
$all << EOD
9.772 0.010749 "cpu pseudo 1 f32 d3 g2"
10.068 0.014797 "cpu random 1 f32 d3 g2"
17.097 0.010749 "opencl pseudo 1 f32 d3 g2"
19.677 0.010814 "cpu random 4 f32 d3 g2"
19.945 0.004830 "cpu pseudo 4 f32 d3 g2"
21.792 0.014797 "opencl random 1 f32 d3 g2"
33.179 0.010814 "opencl random 4 f32 d3 g2"
33.389 0.004830 "opencl pseudo 4 f32 d3 g2"
53.850 0.003347 "cpu random 16 f32 d3 g8"
54.043 0.003347 "cpu random 16 f32 fast d3 g2"
57.093 0.003347 "cpu random 16 f32 d3 g2"
57.259 0.003347 "cpu random 16 f32 d0 g2"
57.272 0.003347 "cpu random 16 f32 d1 g2"
57.329 0.002847 "cpu pseudo 16 f32 d3 g2"
80.525 0.003347 "cpu random 16 f64 d3 g2"
93.872 0.002847 "opencl pseudo 16 f32 d3 g2"
94.289 0.003347 "opencl random 16 f32 d3 g2"
107.001 0.003347 "cpu random 16 f32 d3 g0.25"
206.958 0.001307 "cpu random 64 f32 d3 g2"
209.301 0.001136 "cpu pseudo 64 f32 d3 g2"
341.035 0.001307 "opencl random 64 f32 d3 g2"
341.812 0.001136 "opencl pseudo 64 f32 d3 g2"
811.115 0.000911 "cpu random 256 f32 d3 g2"
816.335 0.000813 "cpu pseudo 256 f32 d3 g2"
1310.331 0.000813 "opencl pseudo 256 f32 d3 g2"
1331.986 0.000911 "opencl random 256 f32 d3 g2"
EOD
$front << EOD
9.772 0.010749 "cpu pseudo 1 f32 d3 g2"
19.945 0.004830 "cpu pseudo 4 f32 d3 g2"
53.850 0.003347 "cpu random 16 f32 d3 g8"
57.329 0.002847 "cpu pseudo 16 f32 d3 g2"
206.958 0.001307 "cpu random 64 f32 d3 g2"
209.301 0.001136 "cpu pseudo 64 f32 d3 g2"
811.115 0.000911 "cpu random 256 f32 d3 g2"
816.335 0.000813 "cpu pseudo 256 f32 d3 g2"
EOD
plot $all using 1:2 with points pt 7 ps 1 lc rgb '#7f7f7f' title 'settings', \
     $front using 1:2 with linespoints pt 7 ps 1.3 lw 2 lc rgb '#d62728' title 'Pareto front', \
     $front using 1:2:3 with labels offset 1,0.6 left font ',8' notitle
