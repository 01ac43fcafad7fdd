% Driver of benchmarks/bench_nlvib.py, case 2: NLvib's EXAMPLES/03_twoDOFoscillator_unilateralSpring,
% its harmonic-balance continuation with the example's parameters copied here (NLvib unchanged):
% masses [1 1], springs [0 1 1], dampers 0.03 * springs, force 0.1 cos(Om t) on the second mass,
% a unilateral spring (stiffness 100, gap 1) on the first; H = 21, N = 2^10, Om from 0.8 down to
% 0.5, ds = 0.0085, Dscale = [1 ... 1, Om_s].
%   nlvib_unilateral(nlvib, dsmin, repeats, outfile)
% dsmin: NLvib's minimum step (its default ds/5 ends the run at Om = 0.58 under Octave's fsolve).
% Writes to outfile: line 1 the wall times, line 2 the CPU times (s) of the continuation (every
% repeat), then one solution point per line: X = [Q0 (2); Qc1 (2); Qs1 (2); ...; Om].
function nlvib_unilateral(nlvib, dsmin, repeats, outfile)
addpath(fullfile(nlvib, 'SRC'));
addpath(fullfile(nlvib, 'SRC', 'MechanicalSystems'));
mi = [1 1];
ki = [0 1 1];
di = .03 * ki;
Fex1 = [0; .1];
nonlinear_elements = struct('type', 'unilateralSpring', 'stiffness', 1e2, 'gap', 1, 'force_direction', [1; 0]);
oscillator = ChainOfOscillators(mi, di, ki, nonlinear_elements, Fex1);
analysis = 'FRF';
H = 21;
N = 2^10;
Om_e = .5;
Om_s = .8;
Q1 = (-Om_s^2 * oscillator.M + 1i * Om_s * oscillator.D + oscillator.K) \ Fex1;
y0 = zeros((2 * H + 1) * length(Q1), 1);
y0(length(Q1) + (1:2 * length(Q1))) = [real(Q1); -imag(Q1)];
ds = .0085;
Sopt = struct('Dscale', [1e-0 * ones(size(y0)); Om_s], 'dsmin', dsmin);
% NLvib's default solver options (solve_and_continue.m), written with optimset('fsolve'): Octave's
% optimset does not take the function handle @fsolve that NLvib's default line passes.
Solopt = optimset(optimset('fsolve'), 'Display', 'off', 'Jacobian', 'on', 'MaxIter', 50);
walls = zeros(1, repeats); cpus = zeros(1, repeats);
for r = 1:repeats
  c0 = cputime; t0 = tic;
  X = solve_and_continue(y0, @(X) HB_residual(X, oscillator, H, N, analysis), Om_s, Om_e, ds, Sopt, {}, Solopt);
  walls(r) = toc(t0); cpus(r) = cputime - c0;
end
fid = fopen(outfile, 'w');
fprintf(fid, '%.9g ', walls); fprintf(fid, '\n');
fprintf(fid, '%.9g ', cpus); fprintf(fid, '\n');
fclose(fid);
dlmwrite(outfile, X', '-append', 'delimiter', ' ', 'precision', '%.17g');
end
