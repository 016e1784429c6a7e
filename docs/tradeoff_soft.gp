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
16.362 0.010815 "cpu pseudo 1 f32 d3 g2"
18.907 0.014378 "cpu random 1 f32 d3 g2"
24.915 0.010815 "opencl pseudo 1 f32 d3 g2"
25.519 0.014378 "opencl random 1 f32 d3 g2"
32.658 0.004825 "cpu pseudo 4 f32 d3 g2"
32.678 0.010338 "cpu random 4 f32 d3 g2"
47.861 0.010338 "opencl random 4 f32 d3 g2"
52.135 0.004825 "opencl pseudo 4 f32 d3 g2"
87.892 0.003261 "cpu random 16 f32 d3 g8"
94.261 0.003261 "cpu random 16 f32 d3 g2"
96.007 0.002885 "cpu pseudo 16 f32 d3 g2"
98.054 0.003261 "cpu random 16 f32 fast d3 g2"
114.051 0.003261 "cpu random 16 f32 d1 g2"
128.247 0.003261 "cpu random 16 f32 d0 g2"
132.839 0.003261 "opencl random 16 f32 d3 g2"
153.024 0.003261 "cpu random 16 f64 d3 g2"
155.924 0.002885 "opencl pseudo 16 f32 d3 g2"
211.686 0.003261 "cpu random 16 f32 d3 g0.25"
324.174 0.001122 "cpu pseudo 64 f32 d3 g2"
348.103 0.001425 "cpu random 64 f32 d3 g2"
479.330 0.001122 "opencl pseudo 64 f32 d3 g2"
493.030 0.001425 "opencl random 64 f32 d3 g2"
1281.774 0.000959 "cpu random 256 f32 d3 g2"
1330.894 0.000729 "cpu pseudo 256 f32 d3 g2"
1928.708 0.000959 "opencl random 256 f32 d3 g2"
1965.406 0.000729 "opencl pseudo 256 f32 d3 g2"
EOD
$front << EOD
16.362 0.010815 "cpu pseudo 1 f32 d3 g2"
32.658 0.004825 "cpu pseudo 4 f32 d3 g2"
87.892 0.003261 "cpu random 16 f32 d3 g8"
96.007 0.002885 "cpu pseudo 16 f32 d3 g2"
324.174 0.001122 "cpu pseudo 64 f32 d3 g2"
1281.774 0.000959 "cpu random 256 f32 d3 g2"
1330.894 0.000729 "cpu pseudo 256 f32 d3 g2"
EOD
plot $all using 1:2 with points pt 7 ps 1 lc rgb '#7f7f7f' title 'settings', \
     $front using 1:2 with linespoints pt 7 ps 1.3 lw 2 lc rgb '#d62728' title 'Pareto front', \
     $front using 1:2:3 with labels offset 1,0.6 left font ',8' notitle
