-- gen_hoodoos_spec.lua — outcrop.generate.hoodoos: the node and its
-- counts against stats(), the default terrain and terrain = false,
-- determinism by seed, the mask (function and heightfield: the field is
-- the bare terrain's wherever the mask is 0), and errors with the script
-- line.
local oc = require "outcrop"
local R = require "helpers.ref"

local F = "gen_hoodoos_spec.lua"
local G = "outcrop.generate.hoodoos"
local function check(f, ...) return R.check_error(f, F, G, ...) end

local hf = oc.heightfield.fbm{size = {81, 81}, cell = 1, wavelength = 30,
                              amplitude = 25, octaves = 4, seed = 7}
local terrain = oc.terrain(hf)

-- field values on a lattice of points a little above the ground
local function probe(node, keep)
  local out = {}
  for y = 5, 75, 2.5 do
    for x = 5, 75, 2.5 do
      if not keep or keep(x, y) then
        out[#out + 1] = node:eval{x, y, hf:height(x, y) + 2}
      end
    end
  end
  return out
end

local function same(a, b)
  if #a ~= #b then return false end
  for i = 1, #a do if a[i] ~= b[i] then return false end end
  return true
end

describe("outcrop.generate.hoodoos", function()
  it("counts its primitives as stats() does", function()
    local n, info = oc.generate.hoodoos{heightfield = hf, seed = 3}
    assert.is_true(info.hoodoos > 10)
    assert.equals(info.primitives, info.blocks + info.cones + info.boxes)
    assert.is_true(info.blocks >= info.hoodoos) -- every word starts with b
    assert.equals(info.primitives + 1, n:stats().primitives) -- + terrain
    local alone, i2 = oc.generate.hoodoos{heightfield = hf, seed = 3,
                                          terrain = false}
    assert.equals(info.primitives, i2.primitives)
    assert.equals(i2.primitives, alone:stats().primitives)
    local given, i3 = oc.generate.hoodoos{heightfield = hf, seed = 3,
                                          terrain = terrain}
    assert.equals(info.primitives + 1, given:stats().primitives)
    assert.equals(info.primitives, i3.primitives)
    -- the hoodoos add to the ground: above it the field only grows
    local a, b = probe(given), probe(terrain)
    local more = 0
    for i = 1, #a do
      assert.is_true(a[i] >= b[i])
      if a[i] > b[i] then more = more + 1 end
    end
    assert.is_true(more > 0)
  end)

  it("is deterministic by seed and differs across seeds", function()
    local a, ia = oc.generate.hoodoos{heightfield = hf, seed = 5}
    local b, ib = oc.generate.hoodoos{heightfield = hf, seed = 5}
    local c = oc.generate.hoodoos{heightfield = hf, seed = 6}
    assert.equals(ia.primitives, ib.primitives)
    assert.is_true(same(probe(a), probe(b)))
    assert.is_false(same(probe(a), probe(c)))
  end)

  it("places nothing where the mask is 0", function()
    local n = oc.generate.hoodoos{heightfield = hf, terrain = terrain, seed = 2,
                                  slope_spread = 10,
                                  mask = function(x, y) return x < 40 and 0 or 1 end}
    -- hoodoos are narrower than 5 m: left of x = 35 only the terrain
    assert.is_true(same(probe(n, function(x) return x < 35 end),
                        probe(terrain, function(x) return x < 35 end)))
    assert.is_false(same(probe(n, function(x) return x > 45 end),
                         probe(terrain, function(x) return x > 45 end)))
    local m = oc.heightfield.from(function(x, y) return y < 40 and 1 or 0 end,
                                  {size = {81, 81}})
    local h = oc.generate.hoodoos{heightfield = hf, terrain = terrain, seed = 2,
                                  slope_spread = 10, mask = m}
    assert.is_true(same(probe(h, function(_, y) return y > 46 end),
                        probe(terrain, function(_, y) return y > 46 end)))
  end)

  it("raises clear errors", function()
    check(function() oc.generate.hoodoos{} end, "'heightfield'")
    check(function() oc.generate.hoodoos{heightfield = 1} end, "'heightfield'")
    check(function() oc.generate.hoodoos{heightfield = hf, radius = -1} end,
          "'radius'")
    check(function() oc.generate.hoodoos{heightfield = hf, radius = 0 / 0} end,
          "'radius'")
    check(function() oc.generate.hoodoos{heightfield = hf, height = {5, 2}} end,
          "'height'")
    check(function() oc.generate.hoodoos{heightfield = hf, height = 3} end,
          "'height'")
    check(function() oc.generate.hoodoos{heightfield = hf, max_depth = 1} end,
          "'max_depth'")
    check(function() oc.generate.hoodoos{heightfield = hf, p_block = 2} end,
          "'p_block'")
    check(function() oc.generate.hoodoos{heightfield = hf, tilt = 3} end,
          "'tilt'")
    check(function() oc.generate.hoodoos{heightfield = hf, colour = 1} end,
          "colour")
    check(function() oc.generate.hoodoos{heightfield = hf, terrain = 3} end,
          "'terrain'")
    check(function() oc.generate.hoodoos{heightfield = hf, mask = "x"} end,
          "'mask'")
    local three, zero = function() return 3 end, function() return 0 end
    check(function() oc.generate.hoodoos{heightfield = hf, mask = three} end,
          "'mask'", "got 3")
    check(function() oc.generate.hoodoos{heightfield = hf, mask = zero, terrain = false} end,
          "no hoodoo")
    check(function() oc.generate.hoodoos{heightfield = hf, radius = 1e-4} end,
          "'radius'")
    local ok, msg = pcall(oc.generate.hoodoos, {heightfield = hf,
      mask = function() error("boom") end})
    assert.is_false(ok)
    assert.truthy(tostring(msg):find("boom", 1, true))
  end)
end)
