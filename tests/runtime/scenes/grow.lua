-- grow.lua [HOW [N]]: uses memory without bound, in Lua (a growing table)
-- or in the engine (HOW: engine, an N x N heightfield, by default 16384 x
-- 16384: 1 GiB); --max-memory must stop it with a clear message.
if arg[1] == "engine" then
  local n = tonumber(arg[2]) or 16384
  local hf = outcrop.heightfield.fbm{size = {n, n}, cell = 1,
                                     wavelength = 100, amplitude = 10}
  print("heightfield made", hf:size())
else
  local t = {}
  for i = 1, math.maxinteger do t[i] = ("x"):rep(64) .. i end
end
error("not reached on purpose")
