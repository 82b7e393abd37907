function sys = load_aeroservo(file)
%LOAD_AEROSERVO  Named state-space model from a file written by aeroservo.
%   SYS = LOAD_AEROSERVO('model.mat') reads a model written by
%       aeroservo export WING --speed V --out model.mat
%   (or aeroservo.files.export_mat in Python) and returns an ss object with
%   the state, input and output names, the airspeed and density in UserData
%   (speed_m_s [m/s], density_kg_m3 [kg/m^3], state_scaling), and the sample
%   time (0: continuous).
%
%   Runs in MATLAB (Control System Toolbox) and in GNU Octave (control
%   package, loaded here with pkg load control; Debian/Ubuntu: apt-get install
%   octave-control). Units: MATLAB puts them in StateUnit, InputUnit and
%   OutputUnit; Octave's ss has no unit properties, so there they are in
%   UserData.state_units, UserData.input_units and UserData.output_units
%   (column cell arrays of char, in the order of the names).
%
%   States: physical x = state_scaling .* x_model when the model was exported
%   balanced (the default; --physical exports the physical states).
%   Units: SI (m, rad, N m, m/s^2, ...); see docs/conventions.md.
%
%   Example (Simulink): sys = load_aeroservo('model.mat'); then an LTI System
%   block with sys, or [A,B,C,D] = ssdata(sys) for a State-Space block.

    octave = exist('OCTAVE_VERSION', 'builtin') > 0;
    if octave
        try
            pkg('load', 'control');
        catch err
            error('load_aeroservo:control', ['load_aeroservo: GNU Octave needs its ' ...
                  'control package (%s); install it with "apt-get install ' ...
                  'octave-control" (Debian/Ubuntu) or "pkg install -forge control"'], ...
                  err.message);
        end
    end
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
    info = struct('speed_m_s', double(d.speed), 'density_kg_m3', double(d.density));
    if isfield(d, 'state_scaling'), info.state_scaling = double(d.state_scaling(:)); end
    unit_fields = {'state_units', 'StateUnit'; 'input_units', 'InputUnit'; ...
                   'output_units', 'OutputUnit'};
    for k = 1:size(unit_fields, 1)
        if isfield(d, unit_fields{k, 1})
            u = names(d.(unit_fields{k, 1}));
            if octave
                info.(unit_fields{k, 1}) = u;
            else
                sys.(unit_fields{k, 2}) = u;
            end
        end
    end
    sys.UserData = info;
end

function c = names(x)
% A column cell array of char from what scipy.io.savemat wrote (cell or char matrix).
    if iscell(x)
        c = cellfun(@(s) strtrim(char(s)), x(:), 'UniformOutput', false);
    else
        c = cellstr(char(x));
    end
end
