function sys = load_aeroservo(file)
%LOAD_AEROSERVO  Named state-space model from a file written by aeroservo.
%   SYS = LOAD_AEROSERVO('model.mat') reads a model written by
%       aeroservo export WING --speed V --out model.mat
%   (or aeroservo.files.export_mat in Python) and returns an ss object with
%   the state, input and output names and units, the airspeed and density in
%   UserData, and the sample time (0: continuous).
%
%   States: physical x = state_scaling .* x_model when the model was exported
%   balanced (the default; --physical exports the physical states).
%   Units: SI (m, rad, N m, m/s^2, ...); see docs/conventions.md.
%
%   Example (Simulink): sys = load_aeroservo('model.mat'); then an LTI System
%   block with sys, or [A,B,C,D] = ssdata(sys) for a State-Space block.

    d = load(file);
    required = {'A', 'B', 'C', 'D', 'state_names', 'input_names', 'output_names'};
    for k = 1:numel(required)
        if ~isfield(d, required{k})
            error('load_aeroservo:format', '%s: not an aeroservo model (no %s)', ...
                  file, required{k});
        end
    end
    dt = 0;
    if isfield(d, 'dt'), dt = double(d.dt); end
    sys = ss(d.A, d.B, d.C, d.D, dt);
    sys.StateName = names(d.state_names);
    sys.InputName = names(d.input_names);
    sys.OutputName = names(d.output_names);
    if isfield(d, 'state_units'), sys.StateUnit = names(d.state_units); end
    if isfield(d, 'input_units'), sys.InputUnit = names(d.input_units); end
    if isfield(d, 'output_units'), sys.OutputUnit = names(d.output_units); end
    info = struct('speed_m_s', double(d.speed), 'density_kg_m3', double(d.density));
    if isfield(d, 'state_scaling'), info.state_scaling = double(d.state_scaling(:)); end
    sys.UserData = info;
end

function c = names(x)
% A column cell array of char from what scipy.io.savemat wrote (cell or char matrix).
    if iscell(x)
        c = cellfun(@(s) strtrim(char(s)), x(:), 'UniformOutput', false);
    else
        c = cellstr(x);
    end
end
