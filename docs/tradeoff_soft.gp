set terminal pngcairo size 1100,700 noenhanced
set output 'docs/tradeoff_soft.png'
set title 'Error against render time, scene soft'
set xlabel 'render time (ms, warm)'
set ylabel 'RMSE against the converged reference'
set logscale xy
set grid
set key top right
$all << EOD
41.330 0.014350 "cpu random 1 f32 d3 g2"
41.466 0.010791 "cpu pseudo 1 f32 d3 g2"
56.146 0.014350 "opencl random 1 f32 d3 g2"
56.723 0.010791 "opencl pseudo 1 f32 d3 g2"
83.932 0.004852 "cpu pseudo 4 f32 d3 g2"
84.722 0.010351 "cpu random 4 f32 d3 g2"
103.594 0.004852 "opencl pseudo 4 f32 d3 g2"
111.698 0.010351 "opencl random 4 f32 d3 g2"
216.545 0.003276 "cpu random 16 f32 fast d3 g2"
242.559 0.003276 "cpu random 16 f32 d3 g8"
257.134 0.003276 "cpu random 16 f32 d3 g2"
257.156 0.002838 "cpu pseudo 16 f32 d3 g2"
257.256 0.003276 "cpu random 16 f32 d0 g2"
257.579 0.003276 "cpu random 16 f32 d1 g2"
283.998 0.003276 "cpu random 16 f64 d3 g2"
299.781 0.003276 "opencl random 16 f32 d3 g2"
305.566 0.002838 "opencl pseudo 16 f32 d3 g2"
462.125 0.003276 "cpu random 16 f32 d3 g0.25"
929.967 0.001228 "cpu pseudo 64 f32 d3 g2"
933.126 0.001435 "cpu random 64 f32 d3 g2"
1082.117 0.001228 "opencl pseudo 64 f32 d3 g2"
1089.978 0.001435 "opencl random 64 f32 d3 g2"
3633.831 0.000824 "cpu pseudo 256 f32 d3 g2"
3649.519 0.000723 "cpu random 256 f32 d3 g2"
4195.986 0.000824 "opencl pseudo 256 f32 d3 g2"
4218.735 0.000723 "opencl random 256 f32 d3 g2"
EOD
$front << EOD
41.330 0.014350 "cpu random 1 f32 d3 g2"
41.466 0.010791 "cpu pseudo 1 f32 d3 g2"
56.723 0.010791 "opencl pseudo 1 f32 d3 g2"
83.932 0.004852 "cpu pseudo 4 f32 d3 g2"
103.594 0.004852 "opencl pseudo 4 f32 d3 g2"
216.545 0.003276 "cpu random 16 f32 fast d3 g2"
257.156 0.002838 "cpu pseudo 16 f32 d3 g2"
305.566 0.002838 "opencl pseudo 16 f32 d3 g2"
929.967 0.001228 "cpu pseudo 64 f32 d3 g2"
1082.117 0.001228 "opencl pseudo 64 f32 d3 g2"
3633.831 0.000824 "cpu pseudo 256 f32 d3 g2"
3649.519 0.000723 "cpu random 256 f32 d3 g2"
4218.735 0.000723 "opencl random 256 f32 d3 g2"
EOD
plot $all using 1:2 with points pt 7 ps 1 lc rgb '#7f7f7f' title 'settings', \
     $front using 1:2 with linespoints pt 7 ps 1.3 lw 2 lc rgb '#d62728' title 'Pareto front', \
     $front using 1:2:3 with labels offset 1,0.6 left font ',8' notitle
