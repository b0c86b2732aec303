-- syntax.lua: the third line does not parse.
local ok = 1
local = 2
