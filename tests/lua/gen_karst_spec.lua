-- gen_karst_spec.lua — outcrop.generate.karst: a node whose cavities sit
-- under the surface and carve it, the budget, determinism by seed, errors.
local oc = require "outcrop"

local function plateau()
  return oc.heightfield.from(function(x, y)
    local r = math.sqrt((x - 128) ^ 2 + (y - 128) ^ 2)
    local t = math.max(0, math.min(1, (r - 70) / 30))
    local z = 20 + 80 * (1 - t * t * (3 - 2 * t))
    return z - 3 * math.exp(-((x - 100) ^ 2 + (y - 100) ^ 2) / 50)
  end, {size = {129, 129}, cell = 2})
end

-- hard rock with a soft bed around z = 94 (as in test_gen_karst.c)
local function geology()
  return oc.geology.layer{origin = {0, 0, 94}, normal = {0, 0, 1}, radius = 10,
                          resistance = -0.6,
                          noise = {wavelength = 10, amplitude = 0.2, offset = 0.7,
                                   octaves = 3, seed = 11}}
end

describe("outcrop.generate.karst", function()
  local hf = plateau()
  local geo = geology()

  it("carves a network of points under the surface, within the budget", function()
    local k, info = oc.generate.karst{heightfield = hf, geology = geo, radius = 4,
                                      max_primitives = 500, seed = 3}
    assert.equals(1, info.sinks)
    assert.is_true(info.primitives > 20 and info.primitives <= 500, info.primitives)
    assert.equals(info.primitives + 1, k:stats().primitives) -- + the terrain
    -- the sink (100, 100) is carved open just under the surface
    local zs = hf:height(100, 100) - 1
    assert.is_true(k:eval(100, 100, zs) < oc.threshold)
    -- far from the network the terrain is untouched
    local t = oc.terrain(hf)
    assert.equals(t:eval(200, 200, 50), k:eval(200, 200, 50))
  end)

  it("is deterministic by seed and differs across seeds", function()
    local function bytes(seed)
      local k = oc.generate.karst{heightfield = hf, geology = geo, radius = 4,
                                  max_primitives = 300, seed = seed, terrain = false}
      local s = {}
      for x = 90, 130, 4 do
        for z = 85, 98, 1 do s[#s + 1] = string.format("%.17g", k:eval(x, 100, z)) end
      end
      return table.concat(s, " ")
    end
    assert.equals(bytes(5), bytes(5))
    assert.are_not.equals(bytes(5), bytes(6))
  end)

  it("takes sinks as points", function()
    local k, info = oc.generate.karst{heightfield = hf, geology = geo, radius = 4,
                                      sinks = {{128, 128, 95}}, max_primitives = 20}
    assert.equals(1, info.sinks)
    assert.equals(20, info.primitives)
    assert.is_true(k:eval(128, 128, 95) < oc.threshold)
  end)

  it("rejects bad options naming the field", function()
    local function err(t, pat)
      local ok, msg = pcall(oc.generate.karst, t)
      assert.is_false(ok)
      assert.matches(pat, msg)
      assert.matches("gen_karst_spec.lua:%d+:", msg)
    end
    err({}, "'heightfield'")
    err({heightfield = 1}, "'heightfield'")
    err({heightfield = hf, radius = -1}, "'radius'")
    err({heightfield = hf, radius = 0 / 0}, "'radius'")
    err({heightfield = hf, rho0 = 2}, "'rho0'")
    err({heightfield = hf, branches = 0}, "'branches'")
    err({heightfield = hf, max_primitives = 0}, "'max_primitives'")
    err({heightfield = hf, geology = "soft"}, "'geology'")
    err({heightfield = hf, terrain = 3}, "'terrain'")
    err({heightfield = hf, sinks = {{-50, 0, 0}}}, "'sinks'")
    err({heightfield = hf, sinks = {{1, 2}}}, "'sinks%[1%]' must be a table of 3 numbers")
    err({heightfield = hf, radius = 1e7}, "'radius'")
    err({heightfield = hf, bogus = 1}, "bogus")
  end)
end)
