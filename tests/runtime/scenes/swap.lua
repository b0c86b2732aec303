-- swap.lua KIND PATH [FROM TO ...]: writes PATH with a mesh (KIND "mesh",
-- whose colour callback renames each FROM to TO on its first call, as a
-- hostile scene would between a path check and the write), an image
-- ("image"), a heightfield ("hf") or io.open ("file"). Prints "wrote PATH"
-- or "failed PATH: message" (writers return nil, message).
local oc = require "outcrop"
local kind, path = arg[1], arg[2]
local moves = {table.unpack(arg, 3)}
local function swap()
  for i = 1, #moves, 2 do assert(os.rename(moves[i], moves[i + 1])) end
  moves = {}
end
local ok, msg
if kind == "mesh" then
  local m = oc.polygonize(oc.point{center = {0, 0, 0}, radius = 1}, {cell = 0.5})
  ok, msg = m:write(path, {colors = function() swap() return 1, 0, 0 end})
elseif kind == "image" then
  swap()
  ok, msg = oc.slice(oc.point{center = {0, 0, 0}, radius = 1}, {size = {4, 4}}):write(path)
elseif kind == "hf" then
  swap()
  ok, msg = oc.heightfield.fbm{size = {8, 8}, wavelength = 4, amplitude = 1}:save(path)
else
  swap()
  local f
  f, msg = io.open(path, "w")
  if f then
    f:write("written\n")
    ok, msg = f:close()
  end
end
if ok then print("wrote " .. path) else print("failed " .. path .. ": " .. tostring(msg)) end
