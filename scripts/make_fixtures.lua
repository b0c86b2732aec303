-- make_fixtures.lua — regenerates the heightmap fixtures under
-- tests/fixtures/ (the files are committed; specs load them). Run from the
-- repository root with the interpreter:
--
--   build/release/outcrop run scripts/make_fixtures.lua --out tests/fixtures
--
-- heightmap16.png: 16-bit PNG, 129 x 97 samples, cell 10 m, origin
-- (-640, -480): fBm hills with a crater, scale and offset in the file's
-- metadata (outcrop:scale, outcrop:offset, outcrop:cell, outcrop:x0,
-- outcrop:y0), as hf:save writes them. tests/lua/heightfield_spec.lua
-- rebuilds the same grid with heightmap() below and compares.
local oc = require "outcrop"

local function heightmap()
  local hills = oc.heightfield.fbm{size = {129, 97}, cell = 10,
    origin = {-640, -480}, wavelength = 400, amplitude = 120, octaves = 6,
    seed = 5}
  -- a crater: a raised rim around a bowl, centred at (150, 60)
  return oc.heightfield.from(function(x, y)
    local r = math.sqrt((x - 150) ^ 2 + (y - 60) ^ 2)
    local rim = 35 * math.exp(-((r - 120) / 40) ^ 2)
    local bowl = r < 120 and -50 * (1 - (r / 120) ^ 2) or 0
    return hills:height(x, y) + rim + bowl
  end, {size = {129, 97}, cell = 10, origin = {-640, -480}})
end

-- Loaded by the spec as a module too: then it only returns the builder.
if ... == "make_fixtures" then return heightmap end

local hf = heightmap()
local scale, offset = hf:save("heightmap16.png")
print(string.format("heightmap16.png: %s; scale %.17g, offset %.17g", tostring(hf), scale, offset))
