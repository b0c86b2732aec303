-- gc_spec.lua — lifetimes: the collector may free userdata in any order,
-- parents keep children alive, deep chains neither recurse nor crash.
local oc = require "outcrop"
local R = require "helpers.ref"
local G = require "helpers.gcstress" -- OUTCROP_GC_STRESS: eager collector

local restore_gc = G.restore

-- A random tree built from a tiny LCG so failures are reproducible.
local function random_tree(seed, depth)
  local s = seed
  local function rnd(n)
    s = (s * 1103515245 + 12345) % 2147483648
    return s % n
  end
  local function build(d)
    if d == 0 or rnd(4) == 0 then
      local k = rnd(4)
      local c = {rnd(5) - 2, rnd(5) - 2, rnd(5) - 2}
      if k == 0 then return oc.point{center = c, radius = 1 + rnd(3)} end
      if k == 1 then return oc.sphere{center = c, radius = 1} end
      if k == 2 then return oc.segment{a = c, b = {0, 0, 0}, radius = 1.5} end
      return oc.box{min = c, max = {c[1] + 1, c[2] + 1, c[3] + 1}}
    end
    local a, b = build(d - 1), build(d - 1)
    local k = rnd(9)
    if k == 0 then return a + b end
    if k == 1 then return a | b end
    if k == 2 then return a & b end
    if k == 3 then return a - b end
    if k == 4 then return -a end
    if k == 5 then return oc.smooth_union{a, b, radius = 0.3} end
    if k == 6 then return oc.warp(a, {wavelength = 2, amplitude = 0.2, control = b}) end
    if k == 7 then return oc.transform(a, {translate = {0.5, 0, 0}, scale = 1.5}) end
    return oc.blend{a, b, a}
  end
  return build(depth)
end

describe("garbage collection", function()
  after_each(restore_gc)

  it("never frees a child still in a tree (setpause 0)", function()
    collectgarbage("setpause", 0)
    collectgarbage("setstepmul", 1000)
    local keep = {}
    for i = 1, 40 do
      local t = random_tree(i, 6)
      local v1 = t:eval(0.3, 0.2, 0.1)
      collectgarbage()
      -- the children's userdata are garbage now; the tree must still work
      assert.are.equal(v1, t:eval(0.3, 0.2, 0.1))
      keep[i % 5] = t
    end
    keep = nil
    collectgarbage()
    collectgarbage()
  end)

  it("survives generational mode while building and dropping", function()
    collectgarbage("generational")
    local sum = 0
    for i = 1, 200 do
      local t = random_tree(1000 + i, 4)
      sum = sum + t:eval(0, 0, 0) + select(1, t:gradient(0.1, 0.1, 0.1))
      local img = oc.slice(t, {box = {-3, -3, 3, 3}, size = {8, 8}})
      sum = sum + img:get(4, 4)
    end
    assert.is_true(sum == sum) -- not NaN
  end)

  it("frees the compiled program with its node", function()
    collectgarbage("setpause", 0)
    for i = 1, 300 do
      local n = oc.point{center = {i, 0, 0}, radius = 1}
      n = n + oc.point{center = {i + 0.5, 0, 0}, radius = 1}
      R.close(n:eval(i, 0, 0), 1 + R.g(0.5), 1e-12)
      oc.threshold = (i % 2 == 0) and 0.5 or 0.4 -- forces recompiles
      n:eval(i, 0, 0)
    end
    oc.threshold = 0.5
  end)

  it("keeps a warp's control node alive", function()
    local base = oc.point{center = {0, 0, 0}, radius = 2}
    local w = oc.warp(base, {wavelength = 1, amplitude = 0.5,
      control = oc.point{center = {40, 0, 0}, radius = 1}})
    collectgarbage(); collectgarbage()
    R.close(w:eval(0.5, 0, 0), base:eval(0.5, 0, 0), 1e-12)
  end)
end)

describe("deep chains #slowgc", function()
  local p = oc.point{center = {0, 0, 0}, radius = 1}

  it("n = n + p, 100000 times, evaluates (blends flatten)", function()
    local n = p
    for _ = 1, 100000 do n = n + p end
    R.close(n:eval(0.5, 0, 0), 100001 * R.g(0.5), 1e-6)
    assert.are.equal(1, n:stats().primitives)
    n = nil
    collectgarbage()
  end)

  it("n = n | q over many primitives (unions flatten)", function()
    local n = p
    for i = 1, 20000 do n = n | oc.point{center = {3 * i, 0, 0}, radius = 1} end
    R.close(n:eval(3 * 777, 0, 0), 1, 1e-12)
    R.close(n:eval(3 * 777 + 1.5, 0, 0), 0, 0)
  end)

  it("a chain of differences becomes one difference", function()
    local big = oc.box{min = {-1, -1, -1}, max = {10001, 1, 1}}
    local n = big
    for i = 1, 10000 do n = n - oc.point{center = {i, 0, 0}, radius = 0.2} end
    R.close(n:eval(5000, 0, 0), 2 * R.T - 1, 1e-12)
    R.close(n:eval(5000.5, 0, 0), 1, 1e-12)
  end)

  -- The limit is 512 nested operators (OC_MAX_DEPTH): a chain of 500
  -- evaluates, one of 5000 is refused by the compiler, never a crash.
  it("chains that cannot flatten evaluate up to the limit, then fail cleanly", function()
    local function chain(n, wrap)
      local c = p
      for _ = 1, n do c = wrap(c) end
      return c
    end
    local function moved(c) return oc.transform(c, {translate = {0, 0, 0}}) end
    local function negated(c) return -c end
    R.close(chain(500, moved):eval(0, 0, 0), 1, 1e-12)
    R.close(chain(500, negated):eval(0, 0, 0), 1, 1e-12)
    local deep = "gc_spec%.lua:%d+: node:eval: tree too deep: more than 512 nested operators"
    local n, m = chain(5000, moved), chain(5000, negated)
    local ok, err = pcall(function() return n:eval(0, 0, 0) end)
    assert.is_false(ok)
    assert.matches(deep, err)
    ok, err = pcall(function() return m:eval(0, 0, 0) end)
    assert.is_false(ok)
    assert.matches(deep, err)
    n, m = nil, nil
    collectgarbage()
  end)

  it("dropping a deep chain frees it without recursion", function()
    local n = p
    for _ = 1, 200000 do n = -n end
    n = nil
    collectgarbage()
    collectgarbage()
  end)
end)
