-- heightfield_spec.lua — outcrop.heightfield: grids from fBm, functions and
-- nodes, the C1 interpolant and its gradient, files (16-bit PNG, 8-bit,
-- float TIFF and EXR round trips, the committed fixture, metadata and
-- provenance), resample and crop, every error with its script line, the
-- same bytes for any thread count, and lifetimes under an eager collector.
local oc = require "outcrop"
local G = require "helpers.gcstress" -- OUTCROP_GC_STRESS: eager collector
local Fs = require "helpers.files"
local read_file = Fs.read_file
local R = require "helpers.ref"

local F = "heightfield_spec.lua"
local function check(f, fname, ...) return R.check_error(f, F, fname, ...) end
local HF = oc.heightfield


local function each_sample(hf)
  local nx, ny = hf:size()
  local i, j = 0, 1
  return function()
    i = i + 1
    if i > nx then i, j = 1, j + 1 end
    if j <= ny then return i, j end
  end
end

local function position(hf, i, j)
  local x0, y0 = hf:bounds()
  return x0 + (i - 1) * hf:cell(), y0 + (j - 1) * hf:cell()
end

local hills = HF.fbm{size = {65, 49}, cell = 2.5, origin = {-30, 12},
  wavelength = 40, amplitude = 25, octaves = 5, seed = 9, offset = 3}

describe("fbm", function()
  it("samples the turbulence node of the same noise on z = 0", function()
    local t = oc.turbulence{wavelength = 40, amplitude = 25, octaves = 5,
      seed = 9, offset = 3}
    for i, j in each_sample(hills) do
      local x, y = position(hills, i, j)
      -- float storage: the node's double rounded to single precision
      assert.are.equal(string.unpack("f", string.pack("f", t:eval(x, y, 0))),
        hills:get(i, j))
    end
    assert.is_true(hills:min() >= 3 and hills:max() <= 3 + 25 * R.tmax(5))
    assert.is_true(hills:max() - hills:min() > 5)
  end)

  it("is the same for the same seed and differs for another", function()
    local function make(seed)
      return HF.fbm{size = {40, 30}, wavelength = 10, amplitude = 1, seed = seed}
    end
    local a, b, c = make(4), make(4), make(5)
    local differ = 0
    for i, j in each_sample(a) do
      assert.are.equal(a:get(i, j), b:get(i, j))
      if a:get(i, j) ~= c:get(i, j) then differ = differ + 1 end
    end
    assert.is_true(differ > 1000)
    -- the default seed is the scene seed (1)
    local d, e = make(nil), make(1)
    assert.are.equal(d:sum(), e:sum())
  end)
end)

describe("queries", function()
  it("report size, cell, bounds, min, max, sum", function()
    local nx, ny = hills:size()
    assert.are.same({65, 49}, {nx, ny})
    assert.are.equal(2.5, hills:cell())
    local lo, hi, sum = math.huge, -math.huge, 0
    for i, j in each_sample(hills) do
      local z = hills:get(i, j)
      lo, hi, sum = math.min(lo, z), math.max(hi, z), sum + z
    end
    assert.are.same({-30, 12, lo, -30 + 64 * 2.5, 12 + 48 * 2.5, hi}, {hills:bounds()})
    assert.are.equal(lo, hills:min())
    assert.are.equal(hi, hills:max())
    assert.is_true(math.abs(hills:sum() - sum) <= 1e-9 * math.abs(sum))
    assert.truthy(tostring(hills):find("^outcrop.heightfield: 65 x 49, cell 2.5, origin %(%-30, 12%)"))
  end)

  it("interpolate through the samples", function()
    for i, j in each_sample(hills) do
      local x, y = position(hills, i, j)
      R.close(hills:height(x, y), hills:get(i, j), 1e-9 * math.abs(hills:get(i, j)))
    end
  end)

  it("give the gradient of the interpolant (central differences)", function()
    local h = 1e-5
    for k = 1, 300 do
      -- inside cells: the interpolant is C1, not C2, across their edges
      local x = -30 + ((k * 0.618034) % 64 + 0.01 + (k % 7) * 0.1) * 2.5
      local y = 12 + ((k * 0.414214) % 48 + 0.02 + (k % 5) * 0.15) * 2.5
      local gx, gy = hills:gradient(x, y)
      local dx = (hills:height(x + h, y) - hills:height(x - h, y)) / (2 * h)
      local dy = (hills:height(x, y + h) - hills:height(x, y - h)) / (2 * h)
      R.close(gx, dx, 1e-5 * (1 + math.abs(dx)))
      R.close(gy, dy, 1e-5 * (1 + math.abs(dy)))
    end
  end)

  it("are C1 across cell edges: the gradient there is the central difference of the samples", function()
    local c, e = 2.5, 1e-9
    for i = 2, 64, 5 do
      for j = 2, 48, 7 do
        local x, y = position(hills, i, j)
        local want_x = (hills:get(i + 1, j) - hills:get(i - 1, j)) / (2 * c)
        local want_y = (hills:get(i, j + 1) - hills:get(i, j - 1)) / (2 * c)
        for _, d in ipairs({{-e, -e}, {e, -e}, {-e, e}, {e, e}}) do
          local gx, gy = hills:gradient(x + d[1], y + d[2])
          R.close(gx, want_x, 1e-6)
          R.close(gy, want_y, 1e-6)
        end
      end
    end
  end)

  it("clamp positions outside the grid (zero gradient across the border)", function()
    assert.are.equal(hills:height(-30, 12), hills:height(-1000, -1000))
    local gx, gy = hills:gradient(-1000, 50)
    assert.are.equal(0, gx)
    assert.are_not.equal(0, gy)
  end)
end)

describe("from", function()
  it("samples a function serially, row by row from the origin", function()
    local calls = {}
    local hf = HF.from(function(x, y)
      calls[#calls + 1] = {x, y}
      return 2 * x - y + 0.5
    end, {size = {4, 3}, cell = 0.5, origin = {1, 2}})
    assert.are.equal(12, #calls)
    assert.are.same({1, 2}, calls[1])
    assert.are.same({2.5, 2}, calls[4])
    assert.are.same({1, 2.5}, calls[5])
    for i, j in each_sample(hf) do
      local x, y = position(hf, i, j)
      assert.are.equal(2 * x - y + 0.5, hf:get(i, j))
    end
  end)

  it("finds the top of a field's surface (a sphere: analytic)", function()
    local rad = 6 + 4 * math.sqrt(1 - 0.5 ^ (1 / 3)) -- r + R ginv(T)
    local s = oc.sphere{center = {10, -4, 3}, radius = 6, falloff = 4}
    local hf = HF.from(s, {size = {33, 33}, cell = 0.75, origin = {-2, -16},
      zrange = {-20, 30}})
    local hits = 0
    for i, j in each_sample(hf) do
      local x, y = position(hf, i, j)
      local d2 = (x - 10) ^ 2 + (y + 4) ^ 2
      if d2 < 0.98 * rad * rad then
        R.close(hf:get(i, j), 3 + math.sqrt(rad * rad - d2), 1e-5)
        hits = hits + 1
      elseif d2 > rad * rad then
        assert.are.equal(-20, hf:get(i, j)) -- no surface: z0
      end
    end
    assert.is_true(hits > 200)
    -- default zrange: the node's z bounds
    local b = HF.from(s, {size = {2, 2}, cell = 30, origin = {10, -4}})
    local _, _, zlo = s:bounds()
    R.close(b:get(1, 1), 3 + rad, 1e-5)
    assert.are.equal(zlo, b:get(2, 1))
    assert.are.equal(zlo, b:min())
    -- the threshold: outcrop.threshold or 'threshold'
    local t = HF.from(s, {size = {2, 2}, origin = {10, -4}, threshold = 0.9})
    R.close(t:get(1, 1), 3 + 6 + 4 * math.sqrt(1 - 0.9 ^ (1 / 3)), 1e-5)
  end)
end)

describe("files", function()
  local dir
  before_each(function() dir = R.tmpdir() end)
  after_each(function() R.rmdir(dir) end)

  it("16-bit PNG: scale and offset use the full range and come back", function()
    local path = dir .. "/h.png"
    local scale, offset = hills:save(path)
    assert.are.equal(hills:min(), offset)
    R.close(scale, (hills:max() - hills:min()) / 65535, 1e-15)
    local back = HF.load(path)
    assert.are.same({hills:bounds()}, {back:bounds()}) -- cell, origin, extremes
    for i, j in each_sample(hills) do
      local q = math.floor((hills:get(i, j) - offset) / scale + 0.5)
      assert.are.equal(string.unpack("f", string.pack("f", q * scale + offset)), back:get(i, j))
    end
    -- quantized elevations save to the same bytes and reload exactly
    -- (once the provenance forgets the load: the second file would list
    -- h.png as an input)
    R.reset_config()
    assert(hills:save(path))
    R.reset_config()
    local s2, o2 = back:save(dir .. "/h2.png")
    assert.are.same({scale, offset}, {s2, o2})
    assert.are.equal(read_file(path), read_file(dir .. "/h2.png"))
  end)

  it("palette pictures: each sample's value through the stops, north up", function()
    -- v = i + 10 j on a 5 x 4 grid, stops 0 -> black, 40 -> white
    local g = HF.from(function(x, y) return x + 10 * y end, {size = {5, 4}})
    local path = dir .. "/p.png"
    g:save(path, {palette = {{0, {0, 0, 0}}, {40, {1, 1, 1}}}})
    local attrs, _, channels = Fs.image_info(path)
    assert.are.equal("R, G, B", channels)
    assert.truthy(attrs["outcrop:version"])
    -- read back the red channel as raw counts (north up: flipped in and out)
    local back = HF.load(path)
    for i, j in each_sample(g) do
      assert.are.equal(math.floor(g:get(i, j) / 40 * 255 + 0.5), back:get(i, j))
    end
    -- palette = true: the default ramp from the grid's min to max
    g:save(dir .. "/d.png", {palette = true})
    local d = HF.load(dir .. "/d.png")
    assert.is_true(d:get(1, 1) < d:get(5, 4))
    check(function() g:save(dir .. "/e.png", {palette = {{1, {0, 0, 2}}}}) end,
          "heightfield:save", "'palette[1]' colour components must be in [0, 1] (got b = 2)")
    check(function() g:save(dir .. "/e.exr", {palette = true}) end,
          "heightfield:save", "a palette picture must be .png or .tif")
  end)

  it("EXR and float TIFF: exact floats", function()
    for _, ext in ipairs({"exr", "tif", "tiff"}) do
      local path = dir .. "/h." .. ext
      assert.are.same({1, 0}, {hills:save(path)})
      local back = HF.load(path)
      assert.are.same({hills:bounds()}, {back:bounds()})
      for i, j in each_sample(hills) do
        assert.are.equal(hills:get(i, j), back:get(i, j))
      end
    end
  end)

  it("8-bit PNG: raw counts 0..255 times scale plus offset", function()
    local path = dir .. "/h8.png"
    local scale, offset = hills:save(path, {bits = 8})
    R.close(scale, (hills:max() - hills:min()) / 255, 1e-12)
    local counts = HF.load(path, {scale = 1, offset = 0})
    assert.are.equal(0, counts:min())
    assert.are.equal(255, counts:max())
    local meters = HF.load(path)
    for i, j in each_sample(counts) do
      local q = counts:get(i, j)
      assert.are.equal(math.floor(q), q)
      assert.is_true(math.abs(meters:get(i, j) - (q * scale + offset)) <= 1e-4)
      assert.is_true(math.abs(meters:get(i, j) - hills:get(i, j)) <= scale / 2 + 1e-4)
    end
    -- given parameters win over the file's
    local moved = HF.load(path, {cell = 7, origin = {1, 2}, scale = 2, offset = -1})
    assert.are.same({1, 2, -1, 1 + 64 * 7, 2 + 48 * 7, 509}, {moved:bounds()})
  end)

  it("RAW 16-bit: little-endian, north row first, the range given back",
     function()
    local g = HF.from(function(x, y) return 10 + x + 100 * y end,
                      {size = {3, 2}})
    -- z from 10 (i = 1, j = 1) to 112 (i = 3, j = 2)
    local s, o, lo, hi = g:save(dir .. "/g.r16")
    assert.are.same({10, 112}, {lo, hi})
    assert.are.equal(10, o)
    assert.is_true(math.abs(s - 102 / 65535) < 1e-15)
    local bytes = read_file(dir .. "/g.r16")
    assert.are.equal(12, #bytes)
    local q = {}
    for k = 1, 6 do q[k] = string.unpack("<I2", bytes, 2 * k - 1) end
    -- first row: j = 2 (y = 1): 110, 111, 112; then j = 1: 10, 11, 12
    local function count(z) return math.floor((z - 10) / s + 0.5) end
    assert.are.same({count(110), count(111), 65535, 0, count(11), count(12)}, q)
    -- back with the range, and with size or without (a square is inferred)
    local back = HF.load(dir .. "/g.r16", {size = {3, 2}, range = {lo, hi}})
    for i, j in each_sample(g) do
      assert.is_true(math.abs(back:get(i, j) - g:get(i, j)) <= s / 2 + 1e-9)
    end
    local sq = HF.from(function(x, y) return x * y end, {size = {4, 4}})
    sq:save(dir .. "/sq.raw", {range = {0, 100}})
    local b2 = HF.load(dir .. "/sq.raw", {range = {0, 100}})
    assert.are.same({4, 4}, {b2:size()})
    assert.is_true(math.abs(b2:get(4, 4) - 9) < 100 / 65535)
    -- counts as they are without a range
    assert.are.equal(65535, HF.load(dir .. "/g.r16", {size = {3, 2}}):get(3, 2))
    -- errors: outside the range, a size that does not fit, options
    local ok, msg = pcall(g.save, g, dir .. "/h.r16", {range = {0, 50}})
    assert.is_false(ok)
    assert.is_truthy(msg:find("outside", 1, true))
    check(function() HF.load(dir .. "/g.r16") end, "outcrop.heightfield.load",
          "square")
    check(function() HF.load(dir .. "/g.r16", {size = {4, 2}}) end,
          "outcrop.heightfield.load", "bytes")
    check(function() HF.load(dir .. "/g.r16", {range = {1, 0 / 0}}) end,
          "outcrop.heightfield.load", "'range'")
    check(function() g:save(dir .. "/h.r16", {range = {5, 5}}) end,
          "heightfield:save", "'range'")
    check(function() g:save(dir .. "/h.r16", {bits = 8}) end,
          "heightfield:save", "'bits'")
    check(function() HF.load(dir .. "/h.png", {size = {3, 2}}) end,
          "outcrop.heightfield.load", "RAW")
    -- the same bytes for 1 and 2 threads is the writer's: no threads here
  end)

  it("arithmetic, clamp, mask and map", function()
    local a = HF.from(function(x, y) return x + 2 * y end, {size = {4, 3}})
    local b = HF.from(function(x, y) return x * y end, {size = {4, 3}})
    for _, c in ipairs{{a + b, function(u, v) return u + v end},
                       {a - b, function(u, v) return u - v end},
                       {a * b, function(u, v) return u * v end},
                       {a + 3, function(u) return u + 3 end},
                       {3 - a, function(u) return 3 - u end},
                       {a * 0.5, function(u) return u * 0.5 end},
                       {2 * a, function(u) return 2 * u end},
                       {-a, function(u) return -u end}} do
      for i, j in each_sample(a) do
        assert.are.equal(c[2](a:get(i, j), b:get(i, j)), c[1]:get(i, j))
      end
    end
    local other = HF.from(function() return 0 end, {size = {4, 3}, cell = 2})
    check(function() return a + other end, "heightfield +", "grids differ")
    check(function() return a + {} end, "heightfield +", "operand 2")
    check(function() return a * (1 / 0) end, "heightfield *", "finite")
    check(function() return a * 1e38 * 1e10 end, "heightfield *", "sample")
    -- clamp, both forms
    local c1, c2 = a:clamp(2, 5), a:clamp{lo = 2, hi = 5}
    for i, j in each_sample(a) do
      local z = math.min(math.max(a:get(i, j), 2), 5)
      assert.are.equal(z, c1:get(i, j))
      assert.are.equal(z, c2:get(i, j))
    end
    assert.are.equal(a:max(), a:clamp{lo = 1}:max())
    check(function() a:clamp(5, 2) end, "heightfield:clamp", "lo <= hi")
    check(function() a:clamp(0 / 0, 2) end, "heightfield:clamp", "lo")
    check(function() a:clamp{lo = 1, hi = 0 / 0} end, "heightfield:clamp", "'hi'")
    -- masks: 0/1, a band, a ramp; terrain masks read them
    local m = a:mask{above = 3}
    for i, j in each_sample(a) do
      assert.are.equal(a:get(i, j) >= 3 and 1 or 0, m:get(i, j))
    end
    local band = a:mask{above = 2, below = 4}
    for i, j in each_sample(a) do
      local z = a:get(i, j)
      assert.are.equal((z >= 2 and z <= 4) and 1 or 0, band:get(i, j))
    end
    local soft = a:mask{above = 3, falloff = 2}
    assert.are.equal(0.5, soft:get(4, 1)) -- z = 3
    assert.are.equal(1, soft:get(3, 2)) -- z = 4: past the ramp
    assert.are.equal(0.25, a:mask{above = 3, falloff = 4}:get(3, 1)) -- z = 2
    check(function() a:mask{} end, "heightfield:mask", "'above', 'below'")
    check(function() a:mask{above = 0 / 0} end, "heightfield:mask", "'above'")
    check(function() a:mask{above = 1, falloff = -1} end, "heightfield:mask",
          "'falloff'")
    local big = HF.fbm{size = {33, 33}, cell = 1, amplitude = 4, wavelength = 9}
    local t = oc.terrain(big, {mask = big:mask{above = 0}})
    assert.are.equal("terrain", t:kind())
    -- map: fn(z, x, y)
    local mm = a:map(function(z, x, y) return z * 10 + x - y end)
    for i, j in each_sample(a) do
      local x, y = position(a, i, j)
      assert.are.equal(a:get(i, j) * 10 + x - y, mm:get(i, j))
    end
    check(function() a:map(function() return "x" end) end, "heightfield:map",
          "sample (1, 1)")
    check(function() a:map(function(z) if z > 3 then return 0 / 0 end return z end) end,
          "heightfield:map", "sample (")
    check(function() a:map(3) end, "heightfield:map", "function")
    -- the source may be closed and collected while fn runs
    local victim = HF.from(function(x) return x end, {size = {5, 5}})
    local out = victim:map(function(z)
      do local c <close> = victim end
      collectgarbage()
      return z + 1
    end)
    check(function() victim:get(1, 1) end, "heightfield:get", "closed")
    assert.are.equal(5, out:get(5, 5))
  end)

  it("fixed scale and offset", function()
    local flat = HF.from(function(x) return 100 + x end, {size = {11, 3}})
    assert.are.same({0.5, 90, 90, 90 + 0.5 * 65535},
                    {flat:save(dir .. "/f.png", {scale = 0.5, offset = 90})})
    local back = HF.load(dir .. "/f.png")
    for i, j in each_sample(flat) do assert.are.equal(flat:get(i, j), back:get(i, j)) end
    local ok, msg = pcall(flat.save, flat, dir .. "/g.png", {scale = 0.001})
    assert.is_false(ok)
    assert.truthy(msg:find("outside", 1, true))
  end)

  it("the committed fixture: 16-bit PNG with its geometry in the metadata", function()
    local hf = HF.load("../fixtures/heightmap16.png")
    local x0, y0, zlo, x1, y1, zhi = hf:bounds()
    assert.are.same({129, 97}, {hf:size()})
    assert.are.same({-640, -480, 640, 480}, {x0, y0, x1, y1})
    assert.are.equal(10, hf:cell())
    -- the grid scripts/make_fixtures.lua builds, to within half a count
    package.path = "../../scripts/?.lua;" .. package.path
    local want = require("make_fixtures")()
    local scale = (want:max() - want:min()) / 65535
    for i, j in each_sample(hf) do
      assert.is_true(math.abs(hf:get(i, j) - want:get(i, j)) <= scale / 2 + 1e-4)
    end
    assert.is_true(zhi - zlo > 100)
    -- the crater: its floor is the lowest ground near (150, 60)
    assert.is_true(hf:height(150, 60) < hf:height(150, 180) - 30)
  end)

  it("carry provenance and geometry as metadata", function()
    local path = dir .. "/p.png"
    hills:save(path)
    local p = io.popen("oiiotool --info -v '" .. path .. "' 2>&1")
    local info = p:read("a")
    p:close()
    for _, key in ipairs({"outcrop:version", "outcrop:seed", "outcrop:scene",
                          "outcrop:cell", "outcrop:x0", "outcrop:scale"}) do
      assert.truthy(info:find(key, 1, true), key .. " missing in\n" .. info)
    end
  end)

  it("fail to write as io.open does: nil and a message, no file left", function()
    local ok, msg = hills:save(dir .. "/no/such/dir/h.png")
    assert.is_nil(ok)
    assert.truthy(msg:find("no/such/dir/h.png", 1, true))
  end)
end)

describe("resample and crop", function()
  it("resample to the same cell reproduces the grid", function()
    local r = hills:resample{cell = 2.5}
    for i, j in each_sample(hills) do assert.are.equal(hills:get(i, j), r:get(i, j)) end
  end)

  it("resample finer: the interpolant at the new samples", function()
    local r = hills:resample{cell = 1.25}
    assert.are.same({129, 97}, {r:size()})
    for i, j in each_sample(r) do
      if i % 9 == 1 and j % 7 == 1 then
        local x, y = position(r, i, j)
        assert.are.equal(string.unpack("f", string.pack("f", hills:height(x, y))), r:get(i, j))
      end
    end
  end)

  it("resample coarser by size: averaged, keeping the extent", function()
    local r = hills:resample{size = {33, 25}}
    assert.are.equal(5, r:cell())
    local x0, y0, _, x1, y1 = r:bounds()
    assert.are.same({-30, 12, 130, 132}, {x0, y0, x1, y1})
    -- a plane stays a plane under the symmetric average (interior)
    local plane = HF.from(function(x, y) return 3 * x - 2 * y end, {size = {41, 41}})
    local p = plane:resample{cell = 4}
    for i = 2, 10 do
      for j = 2, 10 do
        local x, y = position(p, i, j)
        R.close(p:get(i, j), 3 * x - 2 * y, 1e-4)
      end
    end
  end)

  it("crop by 1-based sample indices or by a box", function()
    local c = hills:crop{3, 4, 20, 10}
    assert.are.same({18, 7}, {c:size()})
    local x0, y0 = c:bounds()
    assert.are.same({-30 + 2 * 2.5, 12 + 3 * 2.5}, {x0, y0})
    for i, j in each_sample(c) do assert.are.equal(hills:get(i + 2, j + 3), c:get(i, j)) end
    local b = hills:crop{box = {-26, 19.5, 12.5, 38}}
    local bx0, by0, _, bx1, by1 = b:bounds()
    assert.are.same({-25, 19.5, 12.5, 37}, {bx0, by0, bx1, by1}) -- samples inside
  end)
end)

describe("errors", function()
  it("name the function, the field and the script line", function()
    check(function() HF.fbm{size = {1, 5}, wavelength = 1, amplitude = 1} end,
      "outcrop.heightfield.fbm", "'size'", "2..65535", "item 1 is 1")
    check(function() HF.fbm{size = {8, 8}, amplitude = 1} end,
      "outcrop.heightfield.fbm", "missing field 'wavelength'")
    check(function() HF.fbm{size = {8, 8}, wavelength = 1, amplitude = 0 / 0} end,
      "outcrop.heightfield.fbm", "'amplitude'")
    check(function() HF.fbm{size = {8, 8}, wavelength = 1, amplitude = 1, octave = 3} end,
      "outcrop.heightfield.fbm", "unknown field 'octave'", "did you mean 'octaves'")
    check(function() HF.fbm{size = {8, 8}, wavelength = 1, amplitude = 1, cell = -1} end,
      "outcrop.heightfield.fbm", "'cell' must be a positive number")
    check(function() HF.fbm{size = {60000, 60000}, wavelength = 1, amplitude = 1} end,
      "outcrop.heightfield.fbm", "60000 x 60000", "limit")
    check(function() HF.load(3) end, "outcrop.heightfield.load", "path must be a string")
    check(function() HF.load("no-such-file.png") end,
      "outcrop.heightfield.load", "cannot read 'no-such-file.png'")
    check(function() HF.load("../fixtures/heightmap16.png", {cell = 0}) end,
      "outcrop.heightfield.load", "'cell'")
    check(function() HF.load("../fixtures/heightmap16.png", {scael = 1}) end,
      "outcrop.heightfield.load", "unknown field 'scael'")
    check(function() HF.from(42, {size = {2, 2}}) end,
      "outcrop.heightfield.from", "argument #1 must be a function")
    check(function() HF.from(function() return 0 / 0 end, {size = {2, 2}}) end,
      "outcrop.heightfield.from", "finite elevation", "sample (1, 1)")
    check(function() HF.from(function() return "x" end, {size = {2, 2}}) end,
      "outcrop.heightfield.from", "finite elevation")
    check(function() HF.from(function() return 1 end, {size = {2, 2}, zrange = {0, 1}}) end,
      "outcrop.heightfield.from", "'zrange'")
    check(function() HF.from(oc.plane{origin = {0, 0, 0}, normal = {1, 0, 0}}, {size = {2, 2}}) end,
      "outcrop.heightfield.from", "give 'zrange'")
    check(function() HF.from(oc.point{center = {0, 0, 0}, radius = 1}, {size = {2, 2}, zrange = {1, 0}}) end,
      "outcrop.heightfield.from", "'zrange'", "z0 < z1")
    check(function() hills:height(0 / 0, 1) end, "heightfield:height", "x must be a finite number")
    check(function() hills:gradient(1) end, "heightfield:gradient", "y must be a finite number")
    check(function() hills:get(0, 1) end, "heightfield:get", "i must be an integer in 1..65")
    check(function() hills:get(1, 50) end, "heightfield:get", "j must be an integer in 1..49")
    check(function() hills:resample{} end, "heightfield:resample", "either 'cell' or 'size'")
    check(function() hills:resample{cell = 1, size = {3, 3}} end, "heightfield:resample", "either")
    check(function() hills:resample{cell = 1e-4} end, "heightfield:resample", "at most 65535")
    check(function() hills:resample{cell = 1000} end, "heightfield:resample", "fewer than 2")
    check(function() hills:resample{size = {10, 40}} end, "heightfield:resample", "square")
    check(function() hills:crop{1, 1, 1, 5} end, "heightfield:crop", "2 x 2")
    check(function() hills:crop{1, 1, 66, 5} end, "heightfield:crop", "item 3 (i1)", "1..65")
    check(function() hills:crop{1, 1, 3} end, "heightfield:crop", "{i0, j0, i1, j1}")
    check(function() hills:crop{box = {0, 0, 1, 1}} end, "heightfield:crop", "fewer than 2 x 2")
    check(function() hills:save("h.jpg") end, "heightfield:save", "unknown heightfield format")
    check(function() hills:save("h.png", {bits = 12}) end, "heightfield:save", "'bits' must be 8 or 16")
    check(function() hills:save("h.exr", {scale = 1}) end, "heightfield:save", "8- and 16-bit")
    check(function() hills:save("h.png", {scale = -1}) end, "heightfield:save", "'scale'")
    check(function() hills.size(42) end, "heightfield:size", "expected a heightfield (got 42)")
  end)

  it("a closed grid refuses every method", function()
    local hf = HF.fbm{size = {4, 4}, wavelength = 1, amplitude = 1}
    do local closed <close> = hf end
    assert.are.equal("outcrop.heightfield: (closed)", tostring(hf))
    check(function() hf:height(0, 0) end, "heightfield:height", "closed")
    check(function() hf:save("x.png") end, "heightfield:save", "closed")
  end)
end)

describe("threads", function()
  local build = os.getenv("OUTCROP_TEST_BUILD")

  it("give the same bytes for 1 and 2 threads (interpreter --threads)", function()
    if not build then pending("needs OUTCROP_TEST_BUILD") return end
    local dir = R.tmpdir()
    local f = assert(io.open(dir .. "/t.lua", "w"))
    f:write([[
local oc = require "outcrop"
local H = oc.heightfield
local a = H.fbm{size = {400, 300}, cell = 0.5, wavelength = 30, amplitude = 10, seed = 3}
a:save("fbm.exr")
a:resample{cell = 0.3}:save("fine.exr")
a:resample{cell = 2.2}:save("coarse.exr")
local s = oc.sphere{center = {100, 70, 0}, radius = 40, falloff = 20} + oc.box{min = {0, 0, -5}, max = {200, 150, 3}}
H.from(s, {size = {200, 150}, zrange = {-10, 80}}):save("surface.exr")
]])
    f:close()
    for _, t in ipairs({1, 2}) do
      local cmd = string.format("'%s/outcrop' run '%s/t.lua' --threads %d --out '%s/t%d' 2>&1",
        build, dir, t, dir, t)
      local p = io.popen(cmd)
      local out = p:read("a")
      assert.is_true(p:close(), out)
    end
    for _, name in ipairs({"fbm.exr", "fine.exr", "coarse.exr", "surface.exr"}) do
      local a, b = read_file(dir .. "/t1/" .. name), read_file(dir .. "/t2/" .. name)
      assert.truthy(a and #a > 1000, name)
      assert.is_true(a == b, name .. " differs between 1 and 2 threads")
    end
    R.rmdir(dir)
  end)
end)

describe("heightfield lifetimes", function()
  after_each(G.restore)

  it("survive an eager collector (setpause 0)", function()
    collectgarbage("setpause", 0)
    collectgarbage("setstepmul", 1000)
    local keep = {}
    for k = 1, 30 do
      local g = HF.fbm{size = {20, 20}, wavelength = 5, amplitude = 1, seed = k}
      local r = g:resample{cell = 0.5}:crop{2, 2, 10, 10}
      g = nil
      collectgarbage()
      local f = HF.from(function(x, y) collectgarbage("step"); return r:height(x, y) end,
        {size = {5, 5}, origin = {1, 1}, cell = 0.5})
      keep[k % 3] = f
      assert.are.equal(r:height(1, 1), f:get(1, 1))
    end
    keep = nil
    collectgarbage()
  end)

  it("leave nothing behind when an error is raised midway", function()
    collectgarbage("setpause", 0)
    for _ = 1, 50 do
      pcall(HF.from, function(x) if x > 2 then error("x") end return x end, {size = {5, 5}})
    end
  end)
end)
