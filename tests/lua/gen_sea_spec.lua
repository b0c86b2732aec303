-- gen_sea_spec.lua — outcrop.generate.sea and outcrop.generate.river:
-- determinism by seed, other seeds other primitives, sea erosion confined
-- to the band around sea level, river erosion to the reach of the
-- riverbed, counts against node:stats(), and errors with the script line.
local oc = require "outcrop"
local R = require "helpers.ref"

local F = "gen_sea_spec.lua"
local function check(f, fname, ...) return R.check_error(f, F, fname, ...) end
local H = oc.heightfield

local function smooth(t) t = math.max(0, math.min(1, t)); return t * t * (3 - 2 * t) end

-- A straight coast: sea floor at -12, a cliff around y = 40, plateau 40.
local coast = H.from(function(x, y) return -12 + 52 * smooth((y - 37) / 6) end,
                     {size = {121, 81}, cell = 1})
local land = oc.terrain(coast)

local rng_state = 4321
local function rand(lo, hi)
  rng_state = (rng_state * 1103515245 + 12345) % 2147483648
  return lo + (hi - lo) * rng_state / 2147483648
end

local function sea(seed, extra)
  local t = {heightfield = coast, terrain = land, seed = seed, range = 4,
             radius = 3, spacing = 1.5, steps = 2, strength = 4}
  for k, v in pairs(extra or {}) do t[k] = v end
  return oc.generate.sea(t)
end

describe("outcrop.generate.sea", function()
  it("is deterministic by seed and differs across seeds", function()
    local a, ia = sea(5)
    local b, ib = sea(5)
    local c = sea(6)
    assert.are.equal(ia.primitives, ib.primitives)
    assert.is_true(ia.primitives > 50)
    local differ = 0
    for _ = 1, 3000 do
      local p = {rand(0, 120), rand(25, 55), rand(-6, 6)}
      local fa = a:eval(p)
      assert.are.equal(fa, b:eval(p))
      if fa ~= c:eval(p) then differ = differ + 1 end
    end
    assert.is_true(differ > 50)
  end)

  it("carves only within range + radius of sea level", function()
    for _, level in ipairs({0, 8}) do
      local n = sea(9, {sea_level = level})
      local carved = 0
      for _ = 1, 6000 do
        local p = {rand(0, 120), rand(0, 80), rand(-14, 42)}
        local fe, ft = n:eval(p), land:eval(p)
        assert.is_true(fe <= ft)
        if math.abs(p[3] - level) > 4 + 3 + 1e-9 then
          assert.is_true(math.abs(fe - ft) <= 1e-12)
        elseif ft > 0.5 and fe <= 0.5 then
          carved = carved + 1
        end
      end
      assert.is_true(carved > 5)
    end
  end)

  it("counts its primitives as stats() does (plus the terrain)", function()
    local n, info = sea(3)
    assert.are.equal(info.primitives + 1, n:stats().primitives)
    assert.is_true(info.samples >= info.primitives)
    assert.is_true(info.columns > 0)
  end)

  it("bites further into soft rock", function()
    local soft = oc.box{min = {60, -1e3, -1e3}, max = {1e3, 1e3, 1e3}, falloff = 0.5}
    local n = sea(2, {geology = soft, steps = 3})
    local west, east = 0, 0
    for x = 4, 56, 0.7 do
      for y = 20, 60, 0.7 do
        for z = -3, 3, 1 do
          if land:eval{x, y, z} > 0.5 and n:eval{x, y, z} <= 0.5 then west = west + 1 end
          if land:eval{x + 60, y, z} > 0.5 and n:eval{x + 60, y, z} <= 0.5 then east = east + 1 end
        end
      end
    end
    -- rho = 0 in the west, 1 in the east: e = sigma against beta sigma
    assert.is_true(west > 2 * east + 10)
  end)

  it("works with the heightfield alone", function()
    local n, info = oc.generate.sea{heightfield = coast, range = 4}
    assert.is_true(info.primitives > 0)
    assert.are.equal(info.primitives + 1, n:stats().primitives)
  end)

  it("returns the primitives alone with terrain = false", function()
    local full, i1 = sea(12)
    local alone, i2 = sea(12, {terrain = false})
    assert.are.equal(i1.primitives, i2.primitives)
    assert.are.equal(i2.primitives, alone:stats().primitives)
    for _ = 1, 500 do
      local p = {rand(0, 120), rand(25, 55), rand(-6, 6)}
      assert.is_true(math.abs(alone:eval(p) + land:eval(p) - full:eval(p)) <= 1e-12)
    end
  end)

  it("rejects bad options with the script line", function()
    local g = "outcrop.generate.sea"
    check(function() oc.generate.sea{heightfield = coast, terrain = true} end, g, "'terrain' must be a node or false")
    check(function() oc.generate.sea{} end, g, "'heightfield'")
    check(function() oc.generate.sea{heightfield = 3} end, g, "'heightfield' must be a heightfield")
    check(function() oc.generate.sea{heightfield = coast, rnage = 3} end, g, "unknown field 'rnage'")
    check(function() oc.generate.sea{heightfield = coast, range = -1} end, g, "'range'")
    check(function() oc.generate.sea{heightfield = coast, sea_level = 0 / 0} end, g, "'sea_level'")
    check(function() oc.generate.sea{heightfield = coast, beta = 2} end, g, "'beta'")
    check(function() oc.generate.sea{heightfield = coast, steps = 0} end, g, "'steps'")
    check(function() oc.generate.sea{heightfield = coast, geology = 1} end, g, "'geology' must be a node")
    check(function() oc.generate.sea{heightfield = coast, spacing = 1e-7} end, g, "'spacing'")
    check(function() oc.generate.sea(coast) end, g)
  end)
end)

describe("outcrop.generate.river", function()
  -- a plane falling to -y with a V channel along x = 60
  local valley = H.from(function(x, y) return 0.3 * y + 0.1 * math.abs(x - 60) end,
                        {size = {121, 81}, cell = 1})
  local ground = oc.terrain(valley)

  it("carves along the high stream power cells only", function()
    local pw = valley:stream_power()
    local vals = {}
    for j = 0, 80 do for i = 0, 120 do vals[#vals + 1] = pw:height(i, j) end end
    table.sort(vals)
    local thr = vals[math.floor(0.95 * (#vals - 1)) + 1]
    local bed = {}
    for j = 0, 80 do
      for i = 0, 120 do
        if pw:height(i, j) >= thr then bed[#bed + 1] = {i, j} end
      end
    end
    local n, info = oc.generate.river{heightfield = valley, terrain = ground,
                                      seed = 4, radius = 2}
    local n2 = oc.generate.river{heightfield = valley, terrain = ground,
                                 seed = 4, radius = 2}
    assert.are.equal(info.primitives + 1, n:stats().primitives)
    local reach = 3 + 0.75 + 2 * 2 + 1 + 2 -- banks, rounding, rays, radius
    local near, far = 0, 0
    for _ = 1, 4000 do
      local p = {rand(0, 120), rand(0, 80), rand(-5, 35)}
      local fe, ft = n:eval(p), ground:eval(p)
      assert.are.equal(fe, n2:eval(p))
      assert.is_true(fe <= ft)
      local d2 = math.huge
      for _, b in ipairs(bed) do
        d2 = math.min(d2, (p[1] - b[1]) ^ 2 + (p[2] - b[2]) ^ 2)
      end
      if d2 > reach * reach then
        far = far + 1
        assert.is_true(math.abs(fe - ft) <= 1e-12)
      elseif fe < ft then
        near = near + 1
      end
    end
    assert.is_true(far > 1000 and near > 10)
  end)

  it("rejects bad options with the script line", function()
    local g = "outcrop.generate.river"
    check(function() oc.generate.river{heightfield = valley, banks = -1} end, g, "'banks'")
    check(function() oc.generate.river{heightfield = valley, power = -2} end, g, "'power'")
    check(function() oc.generate.river{heightfield = valley, depth = 0 / 0} end, g, "'depth'")
    check(function() oc.generate.river{heightfield = valley, sea_level = 1} end, g, "unknown field 'sea_level'")
  end)
end)
