-- terrain_spec.lua — outcrop.terrain: the implicit surface embeds the
-- heightfield (bisection on random columns against hf:height), inversion
-- and floating islands, masks, the gradient, the options and their
-- errors (with the script line), a DEM meshed closed, and lifetimes.
local oc = require "outcrop"
local R = require "helpers.ref"

local F = "terrain_spec.lua"
local function check(f, fname, ...) return R.check_error(f, F, fname, ...) end

local hf = oc.heightfield.fbm{size = {65, 49}, cell = 2, amplitude = 12,
                              wavelength = 40, seed = 4}
local X1, Y1 = 128, 96 -- the grid spans [0, 128] x [0, 96]

-- z in [lo, hi] where node crosses T (f > T at lo, f < T at hi, or the
-- reverse)
local function crossing(node, x, y, lo, hi)
  local T = oc.threshold
  local lo_in = node:eval(x, y, lo) > T
  assert.are_not.equal(lo_in, node:eval(x, y, hi) > T)
  for _ = 1, 70 do
    local m = 0.5 * (lo + hi)
    if (node:eval(x, y, m) > T) == lo_in then lo = m else hi = m end
  end
  return 0.5 * (lo + hi)
end

describe("outcrop.terrain", function()
  it("embeds the heightfield on random columns", function()
    local t = oc.terrain(hf, {falloff = 6})
    assert.are.equal("terrain", t:kind())
    local x0, y0, z0, x1, y1, z1 = t:bounds()
    assert.are.same({0, 0, X1, Y1}, {x0, y0, x1, y1})
    math.randomseed(3)
    for _ = 1, 200 do
      local x, y = 6 + math.random() * (X1 - 12), 6 + math.random() * (Y1 - 12)
      local h = hf:height(x, y)
      local z = crossing(t, x, y, z0 + 6 - 0.05, z1)
      assert.is_true(math.abs(z - h) < 1e-3 * 2)
      assert.is_true(t:eval(x, y, h - 0.2) > 0.5 and t:eval(x, y, h + 0.2) < 0.5)
    end
  end)

  it("has sigma's profile: T at the surface, 2T and 0 beyond the transition",
     function()
    local t = oc.terrain(hf, {falloff = 6, transition = 0.75})
    local h = hf:height(60, 40)
    assert.is_true(math.abs(t:eval(60, 40, h) - 0.5) < 1e-12)
    assert.are.equal(0, t:eval(60, 40, h + 0.76))
    assert.are.equal(1, t:eval(60, 40, h - 0.76))
    -- the paper's cubic: T + x + (3T - 2W)/W^2 x^2 + (W - 2T)/W^3 x^3
    local x, W, T = 0.3, 0.75, 0.5
    local s = T + x + (3 * T - 2 * W) / W ^ 2 * x ^ 2 + (W - 2 * T) / W ^ 3 * x ^ 3
    assert.is_true(math.abs(t:eval(60, 40, h - x) - s) < 1e-12)
  end)

  it("has an analytic gradient", function()
    local t = oc.terrain(hf, {falloff = 5})
    math.randomseed(8)
    for _ = 1, 100 do
      local p = {math.random() * X1, math.random() * Y1,
                 hf:height(40, 40) + (math.random() - 0.5) * 30}
      local gx, gy, gz = t:gradient(p[1], p[2], p[3])
      local n = R.numgrad(t, p, 1e-6)
      local e = math.sqrt((gx - n[1]) ^ 2 + (gy - n[2]) ^ 2 + (gz - n[3]) ^ 2)
      assert.is_true(e < 1e-5 * (1 + math.sqrt(n[1] ^ 2 + n[2] ^ 2 + n[3] ^ 2)))
    end
  end)

  it("inverts, and makes floating islands with an inverted terrain",
     function()
    local top = oc.terrain(hf, {falloff = 6})
    local under = oc.heightfield.fbm{size = {65, 49}, cell = 2, amplitude = 3,
                                     wavelength = 30, seed = 9}
    local lo = hf:min() - 12
    local bottom = oc.terrain(under, {falloff = 6, invert = true,
                                      thickness = 200})
    local inv = oc.terrain(hf, {falloff = 6, invert = true})
    local h = hf:height(50, 50)
    assert.is_true(inv:eval(50, 50, h + 0.2) > 0.5)
    assert.is_true(inv:eval(50, 50, h - 0.2) < 0.5)
    local island = top & oc.transform(bottom, {translate = {0, 0, lo}})
    local hb = under:height(50, 50) + lo
    assert.is_true(island:eval(50, 50, 0.5 * (h + hb)) > 0.5)
    assert.is_true(island:eval(50, 50, hb - 0.2) < 0.5)
    assert.is_true(island:eval(50, 50, h + 0.2) < 0.5)
  end)

  it("takes any horizontal domain from a mask", function()
    local m = oc.heightfield.from(function(x, y)
      return ((x - 64) ^ 2 + (y - 48) ^ 2 < 30 ^ 2) and 1 or 0
    end, {size = {65, 49}, cell = 2})
    local t = oc.terrain(hf, {falloff = 4, mask = m})
    local h = hf:height(64, 48)
    assert.is_true(t:eval(64, 48, h - 0.1) > 0.5)
    for _, p in ipairs{{5, 5}, {120, 90}, {64, 85}} do
      for z = -40, 40, 5 do assert.are.equal(0, t:eval(p[1], p[2], z)) end
    end
  end)

  it("meshes a DEM closed", function()
    local t = oc.terrain(hf, {falloff = 6})
    local _, _, z0, _, _, z1 = t:bounds()
    local mesh = oc.polygonize(t, {box = {-1, -1, z0 - 1, X1 + 1, Y1 + 1, z1 + 1},
                                   cell = 1.5})
    local v, tri = mesh:counts()
    -- closed triangle mesh of a slab: 3T = 2E, V - E + T = 2
    assert.are.equal(2, v - tri / 2)
  end)

  it("checks its arguments", function()
    check(function() oc.terrain(42) end, "outcrop.terrain",
          "expected a heightfield")
    check(function() oc.terrain(hf, {falloff = -1}) end, "outcrop.terrain",
          "'falloff'")
    check(function() oc.terrain(hf, {falloff = 0 / 0}) end, "outcrop.terrain",
          "'falloff'")
    check(function() oc.terrain(hf, {falloff = 1e9, edges = "slab"}) end,
          "outcrop.terrain", "'falloff'")
    check(function() oc.terrain(hf, {edges = "closed"}) end, "outcrop.terrain",
          "'edges'")
    check(function() oc.terrain(hf, {edges = "open", mask = hf}) end,
          "outcrop.terrain", "'edges'")
    check(function() oc.terrain(hf, {transition = 0}) end, "outcrop.terrain",
          "'transition'")
    check(function() oc.terrain(hf, {thickness = -2}) end, "outcrop.terrain",
          "'thickness'")
    check(function() oc.terrain(hf, {invert = 1}) end, "outcrop.terrain",
          "'invert'")
    check(function() oc.terrain(hf, {mask = 3}) end, "outcrop.terrain",
          "'mask'")
    check(function() oc.terrain(hf, {mask = "/nonexistent/mask.png"}) end,
          "outcrop.terrain", "'mask'", "mask.png")
    check(function() oc.terrain(hf, {fallof = 2}) end, "outcrop.terrain",
          "fallof")
    check(function() oc.terrain(hf, {}, 3) end, "outcrop.terrain")
  end)

  it("open edges (the default): the grid back from the terrain, border included",
     function()
    local t = oc.terrain(hf)
    local x0, y0, z0, x1, y1, z1 = t:bounds()
    local back = oc.heightfield.from(t, {size = {65, 49}, cell = 2,
                                         zrange = {z0, z1}})
    local worst = 0
    for j = 1, 49 do
      for i = 1, 65 do
        worst = math.max(worst, math.abs(back:get(i, j) - hf:get(i, j)))
      end
    end
    assert.is_true(worst < 1e-4, "off by " .. worst)
    -- f = 0 just off the sides, the surface's on them
    local h = hf:get(1, 10)
    assert.is_true(t:eval(0, 18, h - 0.3) > 0.5)
    assert.are.equal(0, t:eval(-1e-9, 18, h - 0.3))
    -- a closed mesh, its walls on the grid's sides
    local m = oc.polygonize(t, {cell = 1.5})
    local v, tri = m:counts()
    assert.are.equal(2, v - tri / 2) -- closed: V - E + T = 2
    local xmin, xmax = math.huge, -math.huge
    for k = 1, v do
      local x = m:vertex(k)
      xmin, xmax = math.min(xmin, x), math.max(xmax, x)
    end
    assert.is_true(math.abs(xmin) < 1e-4 and math.abs(xmax - X1) < 1e-4)
    -- the slab, as before, ends 2.19 falloffs short of the sides
    local s = oc.terrain(hf, {edges = "slab"})
    assert.are.equal(0, s:eval(1, 18, h - 0.3) > 0.5 and 1 or 0)
  end)

  it("warns when a thin terrain meshes to nothing", function()
    local flat = oc.heightfield.from(function() return 0 end,
                                     {size = {16, 16}})
    local t = oc.terrain(flat, {falloff = 0.01})
    local name = os.tmpname()
    local saved = io.stderr
    -- the warning goes to the process's stderr: run in a child
    local f = assert(io.popen("lua5.4 -e 'package.cpath=[[" .. package.cpath ..
      "]] local oc = require \"outcrop\" " ..
      "local hf = oc.heightfield.from(function() return 0 end, {size = {16, 16}}) " ..
      "local m = oc.polygonize(oc.terrain(hf, {falloff = 0.01}), " ..
      "{box = {-1, -1, -2, 16, 16, 2}, cell = 0.5}) " ..
      "io.write(select(2, m:counts()))' 2>" .. name))
    local out = f:read("a")
    f:close()
    local err = assert(io.open(name)):read("a")
    os.remove(name)
    assert.are.equal("0", out)
    assert.is_truthy(err:find("outcrop: warning: ", 1, true))
    assert.is_truthy(err:find("falloff", 1, true))
    assert.is_truthy(err:find("thickness", 1, true))
    assert.is_truthy(t)
    assert.are.equal(saved, io.stderr)
  end)

  it("warns when a thin terrain renders to (almost) nothing", function()
    -- the warning goes to the process's stderr: run in a child (one
    -- thread: stock lua5.4 may crash at exit unloading libgomp's workers)
    local function child(falloff)
      local name = os.tmpname()
      local f = assert(io.popen("OMP_NUM_THREADS=1 lua5.4 -e 'package.cpath=[[" ..
        package.cpath .. "]] local oc = require \"outcrop\" " ..
        "local hf = oc.heightfield.from(function() return 0 end, {size = {16, 16}}) " ..
        "local img = oc.render(oc.terrain(hf, {falloff = " .. falloff .. "}), " ..
        "{size = {32, 24}, camera = {eye = {-10, -12, 9}, target = {8, 8, 0}}}) " ..
        "local n = 0 for j = 1, 24 do for i = 1, 32 do " ..
        "if select(5, img:get(i, j)) < math.huge then n = n + 1 end end end " ..
        "io.write(n)' 2>" .. name))
      local out = f:read("a")
      f:close()
      local err = assert(io.open(name)):read("a")
      os.remove(name)
      return tonumber(out), err
    end
    local hits, err = child(0.01)
    assert.is_true(hits <= 8, hits .. " pixels")
    assert.is_truthy(err:find("outcrop: warning: (command line):1: outcrop.render: " ..
      "the terrain's solid is", 1, true), err)
    assert.is_truthy(err:find("hit tolerance", 1, true))
    assert.is_truthy(err:find("'thickness'", 1, true))
    hits, err = child(4)
    assert.is_true(hits > 100, hits .. " pixels")
    assert.are.equal("", err)
  end)

  it("keeps its grid alive", function()
    local t = oc.terrain(oc.heightfield.fbm{size = {33, 33}, cell = 1,
                                            amplitude = 2, wavelength = 9})
    collectgarbage()
    collectgarbage()
    assert.is_true(t:eval(16, 16, -50) >= 0)
    assert.is_true(t:lipschitz() > 0)
  end)
end)
